"""Which pick does not fit the others: each pair's leave-one-out miss, normalised by the noise it should have.

For pair i with residual ``r_i`` (2,) and hat block ``H_ii = J_i (J^T J)^-1 J_i^T`` (2, 2), the pose solved
without it misses it by ``d_i = (I - H_ii)^-1 r_i``, whose covariance is ``sigma^2 (I - H_ii)^-1`` for a good
pick; so ``T_i = r_i^T (I - H_ii)^-1 r_i / sigma^2`` is chi-square with 2 degrees of freedom. A pick beyond
the quantile that leaves one solve in a thousand with a false flag (``1 - 0.001 / n`` per pick: 18.4 for 10
pairs, 31 for 5000) is flagged; a 12 px mis-pick among good ones at 0.5 px (``T`` near 500) is not missed.
``sigma`` for pair i is the larger of the noise model's and the scale the *other* picks show (the fit's squared
residuals without pair i's share, over their degrees of freedom: the externally studentised residual), so
consistently coarse picks (2 px by hand on a photo) are not all called mis-picks and a mis-pick does not hide
behind its own residual.
"""

from __future__ import annotations

import numpy as np

FALSE_FLAG_PER_SOLVE = 0.001


def misfit_statistics(jacobian: np.ndarray, residuals: np.ndarray, used: np.ndarray) -> np.ndarray:
    """``r_i^T (I - H_ii)^-1 r_i`` (n,) px^2 for the ``used`` pairs (NaN for the others and where the pair
    carries the pose alone). ``jacobian`` (n, 2, p), ``residuals`` (n, 2) px, ``used`` (n,) bool."""
    n = len(residuals)
    out = np.full(n, np.nan)
    J = jacobian[used]
    if len(J) * 2 <= jacobian.shape[2]:
        return out  # no redundancy: nothing checks anything
    A = np.einsum("nip,niq->pq", J, J)
    try:
        C = np.linalg.inv(A)
    except np.linalg.LinAlgError:
        return out
    for i in np.flatnonzero(used):
        H = jacobian[i] @ C @ jacobian[i].T
        M = np.eye(2) - H
        if np.linalg.det(M) <= 1e-9:
            continue
        out[i] = float(residuals[i] @ np.linalg.solve(M, residuals[i]))
    return out


def threshold(n_pairs: int) -> float:
    """The chi-square (2 dof) limit of one pick's statistic among ``n_pairs``: ``-2 ln(0.001 / n)``."""
    return -2.0 * float(np.log(FALSE_FLAG_PER_SOLVE / max(n_pairs, 1)))


def flag_misfits(statistics: np.ndarray, residuals: np.ndarray, used: np.ndarray, n_params: int, noise_px: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(flags (n,) bool, the sigma used for each pair (n,) px, the limit of the statistic): see the module.
    ``residuals`` (n, 2) px of the fit, ``used`` (n,) the pairs in it, ``n_params`` its unknowns."""
    n = len(statistics)
    finite = np.isfinite(statistics)
    limit = threshold(int(finite.sum()))
    sigma = np.full(n, float(noise_px))
    dof = 2 * int(used.sum()) - n_params - 2  # without pair i: two observations fewer
    if finite.sum() < 3 or dof <= 0:
        return np.zeros(n, dtype=bool), sigma, limit
    rss = float(np.sum(residuals[used] ** 2))
    others = np.where(finite, np.maximum(rss - np.nan_to_num(statistics), 0.0) / dof, 0.0)
    sigma = np.maximum(noise_px, np.sqrt(others))
    # Where the scale is the picks' own estimate, the statistic over it is 2 F(2, dof), not chi-square: the
    # heavier tail of an estimated scale (12 degrees of freedom for 10 pairs) must not flag coarse good picks.
    from scipy.stats import f as fisher

    limits = np.where(np.sqrt(others) > noise_px, 2.0 * fisher.ppf(1.0 - FALSE_FLAG_PER_SOLVE / max(int(finite.sum()), 1), 2, dof), limit)
    with np.errstate(invalid="ignore"):
        return np.nan_to_num(statistics / sigma**2, nan=0.0) > limits, sigma, limit
