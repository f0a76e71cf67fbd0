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

from functools import lru_cache

import numpy as np

from calib_core.solver.kernels.diagnostics import misfit_flags, quadratic_forms

FALSE_FLAG_PER_SOLVE = 0.001
OWN_SCALE_MIN_DOF = 4
"""The picks' own scale replaces the noise model only when measured with this many degrees of freedom: from
fewer (5 pairs: 2) a least-squares pose that absorbed a 5-10 px mis-pick into the others looks like coarse
picks, and the mis-pick passed (a pose 20 mm wrong called ok)."""


def _quadratic_forms(
    jacobian: np.ndarray, residuals: np.ndarray, used: np.ndarray, rows: np.ndarray, sign: float
) -> np.ndarray:
    """``r_i^T (I + sign H_ii)^-1 r_i`` (len(rows),) for the ``rows``, ``H_ii = J_i (J^T J)^-1 J_i^T`` over the ``used``
    pairs (compiled: one pass over the pairs, no (n, 2, 2) arrays). NaN where the block is singular or there is no
    redundancy."""
    out = np.empty(len(rows))
    quadratic_forms(
        np.ascontiguousarray(jacobian, dtype=float),
        np.ascontiguousarray(residuals, dtype=float),
        np.ascontiguousarray(used, dtype=np.bool_),
        np.ascontiguousarray(rows, dtype=np.int64),
        float(sign),
        out,
    )
    return out


def misfit_statistics(jacobian: np.ndarray, residuals: np.ndarray, used: np.ndarray) -> np.ndarray:
    """``r_i^T (I - H_ii)^-1 r_i`` (n,) px^2 for the ``used`` pairs (NaN for the others and where the pair
    carries the pose alone). ``jacobian`` (n, 2, p), ``residuals`` (n, 2) px, ``used`` (n,) bool."""
    out = np.full(len(residuals), np.nan)
    rows = np.flatnonzero(used)
    out[rows] = _quadratic_forms(jacobian, residuals, used, rows, -1.0)
    return out


def prediction_statistics(jacobian: np.ndarray, residuals: np.ndarray, used: np.ndarray) -> np.ndarray:
    """``r_j^T (I + H_jj)^-1 r_j`` (n,) px^2 for the pairs *not* ``used`` by the fit (NaN for the used ones and
    without redundancy): how far the fit's prediction misses pair j, against the prediction's own spread
    (``sigma^2 (I + H_jj)`` for a good pick). Chi-square with 2 degrees of freedom once divided by sigma^2,
    like :func:`misfit_statistics` for the pairs in the fit. Same arguments."""
    out = np.full(len(residuals), np.nan)
    rows = np.flatnonzero(~used)
    out[rows] = _quadratic_forms(jacobian, residuals, used, rows, 1.0)
    return out


def admissible(
    jacobian: np.ndarray, residuals: np.ndarray, used: np.ndarray, n_params: int, noise_px: float
) -> np.ndarray:
    """(n,) bool: the pairs outside the fit (``used`` False) that its pose predicts as well as a good pick's
    noise allows, by :func:`prediction_statistics` against the larger of ``noise_px`` and the fit's own scale
    (its squared residuals over their degrees of freedom; then the limit is 2 F(2, dof), as in
    :func:`flag_misfits`), at the same false-flag rate per solve."""
    statistics = prediction_statistics(jacobian, residuals, used)
    finite = np.isfinite(statistics)
    dof = 2 * int(used.sum()) - n_params
    if not finite.any() or dof <= 0:
        return np.zeros(len(residuals), dtype=bool)
    scale = float(np.sqrt(np.sum(residuals[used] ** 2) / dof)) if dof >= OWN_SCALE_MIN_DOF else 0.0
    sigma = max(float(noise_px), scale)
    tested = len(residuals)
    limit = 2.0 * fisher_quantile(tested, dof) if scale > noise_px else threshold(tested)
    return np.where(finite, statistics, np.inf) / sigma**2 <= limit


@lru_cache(maxsize=4096)
def fisher_quantile(n_tested: int, dof: int) -> float:
    """F(2, dof) at the quantile leaving one false flag per thousand solves among ``n_tested`` pairs."""
    from scipy.special import fdtri  # F's quantile function (scipy.stats costs half a second to import)

    return float(fdtri(2, dof, 1.0 - FALSE_FLAG_PER_SOLVE / max(n_tested, 1)))


def threshold(n_pairs: int) -> float:
    """The chi-square (2 dof) limit of one pick's statistic among ``n_pairs``: ``-2 ln(0.001 / n)``."""
    return -2.0 * float(np.log(FALSE_FLAG_PER_SOLVE / max(n_pairs, 1)))


def flag_misfits(
    statistics: np.ndarray, residuals: np.ndarray, used: np.ndarray, n_params: int, noise_px: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """(flags (n,) bool, the sigma used for each pair (n,) px, the limit of the statistic): see the module.
    ``residuals`` (n, 2) px of the fit, ``used`` (n,) the pairs in it, ``n_params`` its unknowns."""
    n = len(statistics)
    finite = np.isfinite(statistics)
    limit = threshold(int(finite.sum()))
    sigma = np.full(n, float(noise_px))
    dof = 2 * int(used.sum()) - n_params - 2  # without pair i: two observations fewer
    if finite.sum() < 3 or dof <= 0:
        return np.zeros(n, dtype=bool), sigma, limit
    # With fewer than OWN_SCALE_MIN_DOF degrees of freedom, too few to measure a scale: the noise model alone. Where
    # the scale is the picks' own estimate, the statistic over it is 2 F(2, dof), not chi-square: the heavier tail of
    # an estimated scale (12 degrees of freedom for 10 pairs) must not flag coarse good picks.
    flags = np.empty(n, dtype=np.bool_)
    misfit_flags(
        np.ascontiguousarray(statistics, dtype=float),
        np.ascontiguousarray(residuals, dtype=float),
        np.ascontiguousarray(used, dtype=np.bool_),
        dof,
        float(noise_px),
        limit,
        2.0 * fisher_quantile(int(finite.sum()), dof),
        OWN_SCALE_MIN_DOF,
        flags,
        sigma,
    )
    return flags, sigma, limit
