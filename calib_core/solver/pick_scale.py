"""How coarse the picks are, read from the picks themselves, for the robust mode's thresholds.

The robust mode judged every pair against a 0.5 px pick noise: hand picks on a photo (about 2 px) then
fell outside a 2 px inlier threshold, good pairs were rejected, and 7 clean pairs failed or were fitted
on a few of them (182 of 200 scenes flagged good pairs at 2 px; the pose up to 84 mm from the plain
solve's). The scale is measured instead, in two steps that a mis-pick cannot steer:

1. PoseLib's sampler at a generous threshold (:data:`COARSEST_PICKS_PX` of noise: hand picks on a blurred
   photo), so that coarse good picks join the consensus and gross misses (tens of pixels) do not;
2. least squares on that consensus, and its squared residuals over their degrees of freedom *without the pair
   that adds most to them* (exactly what the fit would leave without it, for a linearised fit): one 12 px
   mis-pick among nine 0.5 px picks would raise the plain estimate to 3 px and hide itself behind it. Leaving
   out the largest share makes the estimate low by about a tenth at 20 pairs and a quarter at 7 (2 px picks:
   median 1.8 and 1.45 px): the thresholds then err towards the noise model, and the admission test (which
   measures the scale of the pairs it keeps) readmits good pairs a low threshold left out.

It needs :data:`~calib_core.solver.misfit.OWN_SCALE_MIN_DOF` degrees of freedom after that pair is left out
(6 agreeing pairs): fewer cannot tell coarse picks from a mis-pick absorbed by the others.
The scale only ever raises the noise model (the caller's sigma or the default); it is capped at
:data:`COARSEST_PICKS_PX` (beyond it the solve's RMS limit says the picks do not fit).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from calib_core.solver.candidates import refine_seed
from calib_core.solver.misfit import OWN_SCALE_MIN_DOF, misfit_statistics
from calib_core.solver.problem import PoseProblem
from calib_core.solver.refine import residuals_and_jacobian
from calib_core.solver.sampler import robust_seed

COARSEST_PICKS_PX = 4.0
"""The coarsest pick noise the robust mode expects, px (1-sigma per axis)."""

SCALE_SAMPLE_PAIRS = 300
"""Beyond this many pairs the scale is measured on this many of them, spread over the list."""


def pick_scale_px(problem: PoseProblem, fu: float, fv: float, order: np.ndarray | None = None) -> float | None:
    """The picks' noise (1-sigma per axis, px) as the consensus of the pairs shows it, at most
    :data:`COARSEST_PICKS_PX`; ``None`` when the pairs leave nothing to measure it with (no consensus, or
    no more pairs than the pose has unknowns). Pinhole model; ``order`` as for the sampler."""
    if problem.n_points > SCALE_SAMPLE_PAIRS:
        # the scale of a few hundred pairs is the scale of them all: a second sampler over 5000 pairs cost as much as
        # the rest of the solve (a fixed, spread choice: the same answer every time)
        problem = _subset(problem, np.linspace(0, problem.n_points - 1, SCALE_SAMPLE_PAIRS).round().astype(int))
        order = None
    seed = robust_seed(problem, fu, fv, COARSEST_PICKS_PX, order=order)
    if seed is None:
        return None
    idx = np.flatnonzero(seed.inliers)
    dof = 2 * len(idx) - problem.n_params
    if dof - 2 < OWN_SCALE_MIN_DOF:
        return None
    sub = _subset(problem, idx)
    fit = refine_seed(sub, seed.R, seed.t, fu, fv, None)
    if fit is None or not fit.converged:
        return None
    r, J, _ = residuals_and_jacobian(sub, fit.newton.R, fit.newton.t, fit.fu, fit.fv)
    drops = misfit_statistics(J, r, np.ones(len(idx), dtype=bool))  # what each pair adds to the squared residuals
    if not np.isfinite(drops).any():
        return None
    scale = float(np.sqrt(max(float(np.sum(r**2)) - float(np.nanmax(drops)), 0.0) / (dof - 2)))
    return min(scale, COARSEST_PICKS_PX) if np.isfinite(scale) else None


def _subset(problem: PoseProblem, idx: np.ndarray) -> PoseProblem:
    return replace(
        problem, points_3d=problem.points_3d[idx], points_2d=problem.points_2d[idx], off_image=(), repeated_3d=()
    )
