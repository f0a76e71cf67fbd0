"""The common case in one compiled call: six or more non-coplanar pairs, known focal
lengths, pinhole model, no robust loss. Returns ``None`` whenever the full search is needed
(no DLT seed, no convergence, or a fit worse than the limit)."""

from __future__ import annotations

import numpy as np

from calib_core.solver.finish import noise_px, operator_warnings
from calib_core.solver.kernels.fast_path import dlt_newton_summary
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT
from calib_core.solver.problem import PoseProblem
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus
from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX, uncertainty_from

_MAX_ITERATIONS = 100


def applies(problem: PoseProblem, robust: bool) -> bool:
    return problem.n_points >= 6 and not problem.coplanar and not problem.estimate_focal and problem.model == "pinhole" and not robust


def fast_solve(problem: PoseProblem, sigma_px: float | None, limit_px: float) -> PoseSolution | None:
    """Solve ``problem`` through the compiled fast path, or ``None`` to fall back."""
    intr = problem.intrinsics
    out = dlt_newton_summary(problem.points_3d, problem.points_2d, intr.fu, intr.fv, intr.cx, intr.cy, problem.distortion, _MAX_ITERATIONS, -1.0 if sigma_px is None else float(sigma_px), DEFAULT_SIGMA_PX)
    if out is None:
        return None
    R, t, r, cov, cov_c, loo, scalars = out
    iterations, outcome, rms, sigma, source, condition = scalars
    if int(outcome) not in (CONVERGED, EXACT_FIT) or not rms <= limit_px:
        return None
    obj2cam = np.zeros((4, 4))
    obj2cam[:3, :3] = R
    obj2cam[:3, 3] = t
    obj2cam[3, 3] = 1.0
    return PoseSolution(
        status=SolveStatus.OK, obj2cam=obj2cam, fu=intr.fu, fv=intr.fv, model="pinhole", iterations=int(iterations),
        residuals_px=r, uncertainty=uncertainty_from(cov, cov_c, sigma, int(source), condition), leave_one_out_px=loo,
        outliers=np.zeros(len(r), dtype=bool), candidates=(PoseCandidate(obj2cam, intr.fu, intr.fv, float(rms)),),
        warnings=tuple(operator_warnings(problem, condition, noise_px(sigma_px))),
    )
