"""Turning the chosen refined pose into a :class:`PoseSolution`: outliers, uncertainty,
leave-one-out residuals, status and the warnings an operator should read."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from calib_core.solver.candidates import RefinedPose, refine_seed
from calib_core.solver.errors import point_label, points_label
from calib_core.solver.paper_model import paper_to_metric_jacobian
from calib_core.solver.kernels.newton import FOCAL_RANGE
from calib_core.solver.misfit import flag_misfits, misfit_statistics
from calib_core.solver.problem import PoseProblem
from calib_core.solver.refine import residuals_and_jacobian
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus
from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX, fit_uncertainty

# Beyond this condition number (of the column-scaled Jacobian) the pose is poorly determined.
_POOR_CONDITION = 1e4


def noise_px(sigma_px: float | None) -> float:
    """The pick noise assumed for thresholds: the caller's, or the default 0.5 px."""
    return DEFAULT_SIGMA_PX if sigma_px is None else float(sigma_px)


def _flag_outliers(residuals: np.ndarray, noise: float) -> np.ndarray:
    e = np.linalg.norm(residuals, axis=1)
    spread = 1.4826 * float(np.median(e))
    return e > max(4.0 * noise, 3.0 * spread)


def operator_warnings(problem: PoseProblem, condition_number: float, noise: float = DEFAULT_SIGMA_PX) -> list[str]:
    """What an operator should know about a solve that is not an error."""
    warnings = []
    for i, j in problem.repeated_3d:
        apart = float(np.linalg.norm(problem.points_2d[i] - problem.points_2d[j]))
        if apart > 3.0 * np.sqrt(2.0) * noise:  # two picks of one point differ by more than their noise allows
            warnings.append(
                f"{point_label(i)} and {point_label(j)} are the same 3D point picked {apart:.1f} px apart: one of the "
                "two picks is off"
            )
    intr = problem.intrinsics
    if not (0.0 <= intr.cx <= intr.width and 0.0 <= intr.cy <= intr.height):
        warnings.append(
            f"the principal point ({intr.cx:.1f}, {intr.cy:.1f}) px lies outside the {intr.width}x{intr.height} image: "
            "check the camera file"
        )
    if problem.n_points * 2 <= problem.n_params:
        warnings.append(
            f"{problem.n_points} pairs for {problem.n_params} unknowns: no redundancy, the residuals are zero by "
            "construction and cannot reveal a mis-click"
        )
    if condition_number > _POOR_CONDITION:
        warnings.append(
            f"the pose is poorly determined (condition number {condition_number:.3g}): spread the points over more of "
            "the object and the image"
        )
    if problem.off_image:
        warnings.append(
            f"{points_label(problem.off_image)} lie outside the {problem.intrinsics.width}x{problem.intrinsics.height} "
            "image"
        )
    if problem.model == "paper" and problem.intrinsics.has_distortion:
        warnings.append("the paper's model ignores lens distortion: the picks were undistorted first")
    return warnings


def _at_focal_limit(problem: PoseProblem, fu: float, fv: float) -> str | None:
    """Words for focal lengths within 2 % of the search's range around the camera file's, or None."""
    low, high = FOCAL_RANGE
    for name, f, f0 in (("fu", fu, problem.intrinsics.fu), ("fv", fv, problem.intrinsics.fv)):
        ratio = f / f0
        if ratio > high / 1.02 or ratio < low * 1.02:
            return f"{name} = {f:.0f} px, {ratio:.2f} x the camera file's {f0:.0f} px; the range is {low:g}-{high:g} x"
    return None


def _worst(statistics: np.ndarray, loo: np.ndarray, e: np.ndarray) -> int:
    """The pair that fits worst: the least likely under the noise model, else the largest leave-one-out miss."""
    if np.isfinite(statistics).any():
        return int(np.nanargmax(statistics))
    return int(np.nanargmax(np.where(np.isfinite(loo), loo, e)))


def _ambiguous_reason(candidates: tuple[PoseCandidate, ...]) -> str:
    return f"{len(candidates)} poses fit the picks about equally well; choose one or add a point"


def stated_with_candidates(solution: PoseSolution, candidates: tuple[PoseCandidate, ...]) -> PoseSolution:
    """An ``ok`` ``solution`` of the first candidate stated with all of ``candidates``: ambiguous where there are two
    or more (as :func:`finish_solution` states a fit without a flagged pair)."""
    if len(candidates) < 2:
        return replace(solution, candidates=candidates)
    return replace(solution, status=SolveStatus.AMBIGUOUS, reason=_ambiguous_reason(candidates), candidates=candidates)


def finish_solution(
    problem: PoseProblem,
    chosen: RefinedPose,
    candidates: tuple[PoseCandidate, ...],
    *,
    sigma_px: float | None,
    limit_px: float,
    huber_px: float | None,
) -> PoseSolution:
    """Build the solution for ``chosen``; ``candidates`` all poses that fit about as well."""
    warnings: list[str] = []
    noise = noise_px(sigma_px)
    iterations = chosen.newton.iterations
    outliers = np.zeros(problem.n_points, dtype=bool)
    fitted_already = False  # a consensus fit's residuals and Jacobian are over every pair at the inliers' pose
    if huber_px is not None:
        # a consensus fit has judged each pair already (threshold, then the prediction test); Huber's fit has not
        outliers = ~chosen.inliers if chosen.inliers is not None else _flag_outliers(chosen.newton.residuals, noise)
        inliers = np.flatnonzero(~outliers)
        fitted_already = chosen.inliers is not None and np.array_equal(chosen.inliers, ~outliers)
        if outliers.any() and len(inliers) >= (4 if problem.estimate_focal else 3) and not fitted_already:
            # Least squares on the inliers alone: the Huber fit still leans slightly on the outliers.
            # (checked already: a subset of checked pairs needs no second check)
            sub = replace(
                problem,
                points_3d=problem.points_3d[inliers],
                points_2d=problem.points_2d[inliers],
                off_image=(),
                repeated_3d=(),
            )
            again = refine_seed(sub, chosen.obj2cam[:3, :3], chosen.obj2cam[:3, 3], chosen.fu, chosen.fv, None)
            if again is not None and again.converged:
                iterations += again.newton.iterations
                chosen = again
        if outliers.any():
            warnings.append(
                f"{points_label(np.flatnonzero(outliers))} rejected as outliers (robust fit); check those picks"
            )
    residuals, jacobian = chosen.newton.residuals, chosen.newton.jacobian
    if outliers.any() and not fitted_already:
        # The inlier re-fit's own arrays lack the outliers: evaluate every point at the final pose.
        residuals, jacobian, _ = residuals_and_jacobian(problem, chosen.newton.R, chosen.newton.t, chosen.fu, chosen.fv)
    weights = (~outliers).astype(float)
    to_metric = (
        paper_to_metric_jacobian(chosen.newton.t, problem.intrinsics, chosen.fu, chosen.fv, problem.n_params)
        if problem.model == "paper"
        else None
    )
    rms, e, loo, uncertainty = fit_uncertainty(
        jacobian, residuals, weights, chosen.obj2cam[:3, :3], chosen.obj2cam[:3, 3], sigma_px, to_metric
    )
    status, reason = SolveStatus.OK, None
    agreeing = int(np.count_nonzero(~outliers))
    statistics = misfit_statistics(jacobian, residuals, ~outliers)
    misfits, sigma_test, limit = flag_misfits(statistics, residuals, ~outliers, problem.n_params, noise)
    if not chosen.converged:
        status, reason = SolveStatus.FAILED, f"Newton iterations stopped: {chosen.newton.reason}"
    elif problem.estimate_focal and (clamp := _at_focal_limit(problem, chosen.fu, chosen.fv)) is not None:
        # The search stops the focal lengths at a range around the camera file's: a solve resting there did not
        # find a camera, and blaming the worst pick would send the operator after good picks.
        status = SolveStatus.FAILED
        reason = (
            f"the focal lengths ran to the edge of their search range ({clamp}): the pairs do not determine them; "
            "spread the picks over the image and in depth, or solve with the camera file's focal lengths"
        )
    elif outliers.any() and 2 * agreeing - problem.n_params < 2:
        # The pairs left fit exactly by construction: nothing checks them, and a mis-click among them
        # would pass unseen (5 pairs, one off: three fitted exactly, two good ones rejected, 550 mm wrong).
        status = SolveStatus.FAILED
        reason = (
            f"only {agreeing} pairs agree after rejecting {points_label(np.flatnonzero(outliers))}: too few to check "
            "one another; "
            "pick the rejected pairs again or add pairs"
        )
    elif rms > limit_px:
        worst = _worst(statistics, loo, e)
        status = SolveStatus.FAILED
        advice = (
            "check that pick" if huber_px is not None else "check that pick, or use robust"
        )  # (robust is on already)
        reason = (
            f"reprojection RMS {rms:.2f} px exceeds {limit_px:.2f} px: the picks do not fit one pose; "
            f"{point_label(worst)} fits worst ({advice})"
        )
    elif misfits.any():
        # A single mis-pick among good ones barely moves the RMS (12 px among 9 good: 0.92 px) but tilts the pose.
        worst = _worst(statistics, loo, e)
        status = SolveStatus.FAILED
        others = (
            f" (also {points_label([i for i in np.flatnonzero(misfits) if i != worst])})" if misfits.sum() > 1 else ""
        )
        reason = (
            f"{point_label(worst)} does not fit the others: the pose from the other pairs misses it by "
            f"{loo[worst]:.1f} px, "
            f"where picks good to {sigma_test[worst]:.2g} px allow about {np.sqrt(limit) * sigma_test[worst]:.1f} "
            f"px{others}; check that pick or untick it"
        )
    elif len(candidates) > 1:
        status, reason = SolveStatus.AMBIGUOUS, _ambiguous_reason(candidates)
    warnings += operator_warnings(problem, uncertainty.condition_number, noise)
    return PoseSolution(
        status=status,
        obj2cam=chosen.obj2cam,
        fu=chosen.fu,
        fv=chosen.fv,
        model=problem.model,
        iterations=iterations,
        residuals_px=residuals,
        uncertainty=uncertainty,
        leave_one_out_px=loo,
        outliers=outliers,
        candidates=candidates,
        reason=reason,
        warnings=tuple(warnings),
        misfits=misfits,
    )
