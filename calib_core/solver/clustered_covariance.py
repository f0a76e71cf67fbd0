"""A least-squares fit's covariance when its residuals come in groups that share an error.

The textbook ``sigma^2 (J^T J)^-1`` takes every residual as independent. Samples along one edge
share the edge's lighting and bevel; the corners of one board view share that view's blur and the
board's flatness there: a hundred of them are fewer independent measurements than a hundred. The
cluster-robust ("sandwich") estimate takes each group's summed score as one measurement::

    cov = H^-1 (G / (G - 1) sum_g s_g s_g^T) H^-1,   s_g = sum over the group's rows of J_i r_i

(``r`` the weighted residuals, ``H = J^T J``), floored in every direction by the independent
residuals' scatter: with few groups the clustered sum alone is noisy and can come out small.
"""

from __future__ import annotations

import numpy as np


def clustered_scatter(J: np.ndarray, residuals: np.ndarray, groups: np.ndarray, independent: np.ndarray) -> np.ndarray:
    """The scatter (p, p) of the normal equations with the rows of each group (``groups`` (m,) int >= 0)
    taken as one measurement, from ``J`` (m, p) and the weighted ``residuals`` (m,); never less than
    ``independent`` (p, p: ``sigma^2 J^T J`` for independent rows) in any direction. Rows with a zero
    residual (weighted out) do not count."""
    used = residuals != 0
    sums = np.zeros((int(groups.max()) + 1 if len(groups) else 1, J.shape[1]))
    np.add.at(sums, groups[used], J[used] * residuals[used, None])
    count = int(np.count_nonzero(np.any(sums != 0, axis=1)))
    clustered = sums.T @ sums * (count / max(count - 1, 1))
    excess, vectors = np.linalg.eigh(clustered - independent)
    return independent + (vectors * np.clip(excess, 0, None)) @ vectors.T
