"""The whole solve for many points in one compiled call: DLT seed, Newton, fit summary.

Most operator solves have six or more well-spread points; for them one call replaces a
dozen interpreter round trips (the solve then costs less than OpenCV's own refinement).
When the seed or the fit is not good enough the caller falls back to the full search.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from calib_core.solver.kernels.camera_models import PINHOLE
from calib_core.solver.kernels.diagnostics import fit_summary
from calib_core.solver.kernels.dlt import dlt_pose
from calib_core.solver.kernels.newton import newton

# Fixed-point undistortion sweeps for the seed: the Newton iterations absorb what is left.
_SEED_UNDISTORT_SWEEPS = 8


@njit(cache=True)
def seed_coordinates(uv, fu, fv, cx, cy, dist):
    """Approximately undistorted normalized coordinates (n, 2) of pixels (n, 2), for seeding."""
    k1, k2, p1, p2, k3 = dist[0], dist[1], dist[2], dist[3], dist[4]
    n = uv.shape[0]
    xy = np.empty((n, 2))
    for i in range(n):
        xd = (uv[i, 0] - cx) / fu
        yd = (uv[i, 1] - cy) / fv
        x, y = xd, yd
        for _ in range(_SEED_UNDISTORT_SWEEPS):
            r2 = x * x + y * y
            radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
            x = (xd - (2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x))) / radial
            y = (yd - (p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y)) / radial
        xy[i, 0] = x
        xy[i, 1] = y
    return xy


@njit(cache=True)
def dlt_newton_summary(P, uv, fu, fv, cx, cy, dist, max_iterations, sigma_given, default_sigma):
    """Seed by DLT, refine, summarise. Returns ``None`` without a DLT seed, else
    ``(R, t, residuals, covariance (6, 6), centre covariance (3, 3), leave-one-out (n,),
    scalars)`` with ``scalars`` = ``iterations, outcome, rms px, sigma px, sigma source,
    condition`` (all arrays allocated here: one call, few interpreter round trips)."""
    n = P.shape[0]
    R = np.empty((3, 3))
    t = np.empty(3)
    if not dlt_pose(P, seed_coordinates(uv, fu, fv, cx, cy, dist), R, t):
        return None
    r = np.empty((n, 2))
    J = np.empty((n, 2, 6))
    f = np.array([fu, fv])
    iterations, outcome = newton(PINHOLE, P, uv, R, t, f, cx, cy, dist, False, False, 0.0, max_iterations, True, r, J)
    cov = np.empty((6, 6))
    cov_centre = np.empty((3, 3))
    loo = np.empty(n)
    lengths = np.empty(n)
    rms, sigma, source, condition = fit_summary(J, r, np.ones(n), R, t, sigma_given, default_sigma, cov, cov_centre, loo, lengths)
    scalars = np.array([iterations, outcome, rms, sigma, source, condition], dtype=np.float64)
    return R, t, r, cov, cov_centre, loo, scalars
