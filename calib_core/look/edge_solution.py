"""The edge refinement as a solve like any other: a :class:`~calib_core.solver.solution.PoseSolution`
with status, covariance and the edge samples' offsets as its residuals (``method`` ``edges``)."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus
from calib_core.solver.uncertainty import uncertainty_from
from calib_core.look.edge_refinement import EdgeFit


def _to_solver_covariance(covariance: np.ndarray, t_mm: np.ndarray) -> np.ndarray:
    """(rotation vector, translation) of the edge fit's left perturbation to the solver's (dt, phi):
    ``t' = exp(phi) t + dt'`` makes ``dt = dt' - [t]x phi``."""
    tx, ty, tz = t_mm
    cross = np.array([[0.0, -tz, ty], [tz, 0.0, -tx], [-ty, tx, 0.0]])
    A = np.zeros((6, 6))
    A[:3, 3:] = np.eye(3)
    A[:3, :3] = -cross
    A[3:, :3] = np.eye(3)
    return A @ covariance @ A.T


def edge_solution(fit: EdgeFit, intrinsics: Intrinsics) -> PoseSolution:
    """``fit`` as a solution: ``ok`` when it settled (:attr:`EdgeFit.settled`)."""
    t = fit.obj2cam[:3, 3]
    R = fit.obj2cam[:3, :3]
    cov = _to_solver_covariance(fit.covariance, t)
    Rt = R.T
    tx, ty, tz = t
    t_cross = np.array([[0.0, -tz, ty], [tz, 0.0, -tx], [-ty, tx, 0.0]])
    B = np.hstack([-Rt, -Rt @ t_cross])  # the camera centre c = -R^T t
    cov_centre = B @ cov @ B.T
    condition = float(np.linalg.cond(fit.covariance)) if np.all(np.isfinite(fit.covariance)) else float("inf")
    uncertainty = uncertainty_from(cov, cov_centre, fit.sigma_px, 1, condition)
    m = len(fit.residuals_px)
    settled = fit.settled
    reason = (
        None
        if settled
        else (
            f"the edges did not settle: RMS {fit.rms_px:.2f} px, {100 * fit.inlier_share:.0f} % of {fit.samples} "
            "samples on their edges"
            if fit.converged
            else "the edge refinement did not converge"
        )
    )
    return PoseSolution(
        status=SolveStatus.OK if settled else SolveStatus.FAILED,
        obj2cam=fit.obj2cam.copy(),
        fu=intrinsics.fu,
        fv=intrinsics.fv,
        model="pinhole",
        iterations=0,
        residuals_px=np.asarray(fit.residuals_px, dtype=float).reshape(-1, 2),
        uncertainty=uncertainty,
        leave_one_out_px=np.full(m, np.nan),
        outliers=np.zeros(m, dtype=bool),
        candidates=(PoseCandidate(fit.obj2cam.copy(), intrinsics.fu, intrinsics.fv, fit.rms_px),),
        reason=reason,
        warnings=(f"solved on {fit.samples} edge samples of the target (no point pairs)",),
        method="edges",
    )
