"""Least squares on some of the pairs, judged on all of them, compiled: the step a consensus repeats.

A robust solve fits the pose to the pairs it agrees with, looks again at every pair from there, and fits again
until the set stays (:func:`calib_core.solver.consensus.consensus_refine`). Each round in Python made a sub-problem,
refined it and evaluated every pair: a dozen interpreter round trips and copies, more than the arithmetic for a few
dozen pairs. Here the rounds run in one call.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from calib_core.solver.kernels.camera_models import PINHOLE, evaluate
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT, newton

# Why a fit stopped short (the caller gives up the consensus): ``FITTED`` otherwise.
FITTED, TOO_FEW, NO_FIT = 0, 1, 2


@njit(cache=True)
def fit_subset_rounds(
    P, uv, R, t, f, cx, cy, dist, focal, inliers, threshold_px, rounds, max_iterations, minimal, r, J
):
    """From the state ``(R (3, 3), t (3,) mm, f (2,) px)``, updated in place: least squares (pinhole) on the pairs
    ``inliers`` (n,) bool, then every pair's residual (``r`` (n, 2) px) and Jacobian (``J`` (n, 2, p)) at that pose,
    and the pairs within ``threshold_px`` of it become ``inliers`` (in place) for the next round; at most ``rounds``,
    ending when the set stays. Returns ``(code, iterations, outcome)``: ``TOO_FEW`` when fewer than ``minimal`` pairs
    are left, ``NO_FIT`` when a fit could not start (a pair behind the camera) or left non-finite residuals, else
    ``FITTED`` with the last fit's Newton iterations and outcome code."""
    n = P.shape[0]
    p = J.shape[2]
    iterations, outcome = 0, 0
    for _ in range(rounds):
        count = 0
        for i in range(n):
            if inliers[i]:
                count += 1
        if count < minimal:
            return TOO_FEW, iterations, outcome
        Ps = np.empty((count, 3))
        uvs = np.empty((count, 2))
        k = 0
        for i in range(n):
            if inliers[i]:
                Ps[k] = P[i]
                uvs[k] = uv[i]
                k += 1
        rs = np.empty((count, 2))
        Js = np.empty((count, 2, p))
        iterations, outcome = newton(
            PINHOLE, Ps, uvs, R, t, f, cx, cy, dist, focal, False, 0.0, max_iterations, True, rs, Js
        )
        if iterations == 0 and outcome != CONVERGED and outcome != EXACT_FIT:
            return NO_FIT, iterations, outcome
        for i in range(count):
            if not (np.isfinite(rs[i, 0]) and np.isfinite(rs[i, 1])):
                return NO_FIT, iterations, outcome
        evaluate(PINHOLE, P, uv, R, t, f[0], f[1], cx, cy, dist, focal, False, r, J)
        same = True
        for i in range(n):
            within = r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1] < threshold_px * threshold_px
            if within != inliers[i]:
                same = False
            inliers[i] = within
        if same:
            break
    return FITTED, iterations, outcome
