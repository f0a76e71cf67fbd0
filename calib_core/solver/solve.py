"""``solve_pose``: the camera pose from point pairs, with no starting pose needed.

Every seed (P3P roots, SQPnP, IPPE, the prior) is refined by the damped Newton solver;
the refined poses that fit about as well as the best are all returned, ranked by
closeness to the prior (the modelled camera pose) when there is one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import check_transform, rotation_angle_deg
from calib_core.solver.candidates import distinct_poses, refine_seed, same_pose
from calib_core.solver.fast_solve import Tie, applies as fast_path_applies, fast_solve
from calib_core.solver.initialisation import SMALL_PROBLEM_POINTS, distinct_seeds, initial_seeds, subset_p3p_seeds
from calib_core.solver.consensus import (
    by_consensus,
    consensus_refine,
    inlier_threshold_px,
    other_minima,
    rival_consensus,
)
from calib_core.solver.sampler import robust_seed
from calib_core.solver.pick_scale import pick_scale_px
from calib_core.solver.problem import PoseProblem, check_in_front, first_of_each_pair, make_problem
from calib_core.solver.errors import RepeatedPairError, named_points_as_given, point_label, points_label
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus, pose_matrix
from calib_core.solver.finish import stated_with_candidates, finish_solution, noise_px
from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX

# Candidates whose cost exceeds the best by less than this many sigma^2 fit "about equally well"
# (a 3-sigma difference in chi-square).
_AMBIGUITY_CHI2 = 9.0


def _check_sigma(sigma_px: float | None) -> None:
    if sigma_px is not None and not (np.isfinite(sigma_px) and sigma_px > 0):
        raise ValueError(f"sigma_px must be a positive number of pixels, got {sigma_px}")


def _distance_to_prior_mm(pose, prior: np.ndarray, intrinsics: Intrinsics) -> float:
    """How far a refined pose is from the prior, mm: translation difference, plus the rotation
    difference as arc length at the prior's object distance, plus (when the focal lengths were
    estimated) their relative change times that distance, which is what it trades against."""
    distance = float(np.linalg.norm(prior[:3, 3]))
    dt = float(np.linalg.norm(pose.obj2cam[:3, 3] - prior[:3, 3]))
    angle_rad = np.radians(rotation_angle_deg(pose.obj2cam[:3, :3] @ prior[:3, :3].T))
    focal = abs(pose.fu / intrinsics.fu - 1.0) + abs(pose.fv / intrinsics.fv - 1.0)
    return dt + (angle_rad + focal) * distance


def _prepare(
    points_3d, points_2d, intrinsics, prior, estimate_focal, model, sigma_px
) -> tuple[PoseProblem, np.ndarray | None]:
    problem = make_problem(points_3d, points_2d, intrinsics, estimate_focal=estimate_focal, model=model)
    _check_sigma(sigma_px)
    prior2 = None
    if prior is not None:
        prior2 = check_transform(prior, name="prior (obj2cam)")
        check_in_front(problem.points_3d, prior2, "prior pose")
    return problem, prior2


def solve_pose(
    points_3d: ArrayLike,
    points_2d: ArrayLike,
    intrinsics: Intrinsics,
    *,
    prior: ArrayLike | None = None,
    estimate_focal: bool = False,
    model: str = "pinhole",
    sigma_px: float | None = None,
    robust: bool = False,
    max_rms_px: float | None = None,
    confidence: ArrayLike | None = None,
) -> PoseSolution:
    """Solve the object-to-camera pose from point pairs.

    ``points_3d`` (n, 3) mm in the object frame; ``points_2d`` (n, 2) px as observed (lens
    distortion is modelled through ``intrinsics``); ``prior`` (4, 4) the modelled
    ``obj2cam``, used to rank ambiguous solutions (never needed to converge);
    ``estimate_focal`` solves fu and fv too (4 pairs or more); ``model`` ``"pinhole"``
    or ``"paper"`` (the paper's biased model, to reproduce it); ``sigma_px`` the pick
    noise (estimated from the residuals when omitted and there is redundancy);
    ``robust`` uses Huber's loss and flags outliers; ``max_rms_px`` the largest RMS
    accepted as a fit (default five times the noise); ``confidence`` (n,) in [0, 1], a detector's
    confidence in each pair: the robust sampler draws from the most confident first (PROSAC).

    A pair given more than once (the same 3D point at the same pixel: a detector's keypoints at two
    scales) is counted once, with a warning; the per-pair arrays still have one row per pair given.

    Raises a :class:`~calib_core.solver.errors.SolverInputError` subclass for bad input.
    Non-convergence and poor fits are a ``failed`` status with a reason.
    """
    try:
        problem, prior2 = _prepare(points_3d, points_2d, intrinsics, prior, estimate_focal, model, sigma_px)
    except RepeatedPairError as repeated:
        # (found by the checks every solve makes: the common case pays nothing for this)
        first = first_of_each_pair(points_3d, points_2d, repeated.same_pixel)
        if np.all(first == np.arange(len(first))):
            raise
        return _solve_distinct(
            first,
            points_3d,
            points_2d,
            intrinsics,
            prior=prior,
            estimate_focal=estimate_focal,
            model=model,
            sigma_px=sigma_px,
            robust=robust,
            max_rms_px=max_rms_px,
            confidence=confidence,
        )
    fu0, fv0 = intrinsics.fu, intrinsics.fv
    order = _confidence_order(confidence, problem.n_points)
    noise = floor = noise_px(sigma_px)
    if robust and problem.model == "pinhole" and sigma_px is None:
        # thresholds at the picks' own scale where it is coarser than the default noise model (hand picks on a photo);
        # a caller who states the noise (a detector's) has it taken as stated
        noise = max(noise, pick_scale_px(problem, fu0, fv0, order) or 0.0)
    limit = 5.0 * noise if max_rms_px is None else float(max_rms_px)
    huber = 2.0 * noise if robust else None

    tie = None
    if fast_path_applies(problem, robust):
        # A DLT seed (many points) or P3P's roots (a few) refined to one good fit is the answer; the
        # other seeds cost more than the whole solve.
        answer = fast_solve(problem, sigma_px, limit, _AMBIGUITY_CHI2)
        if isinstance(answer, PoseSolution):
            return answer
        tie = answer if isinstance(answer, Tie) else None
    sampled = robust_seed(problem, fu0, fv0, noise, order=order) if robust else None
    # With a sampled seed the all-points seeds add nothing: outliers spoil them, and on a clean set the
    # sampler's seed is theirs.
    # (no gate when robust: it ranks the triplets' roots by all the pairs' RMS, outliers included, and
    # could keep a wrong root that spreads an outlier's error over good pairs and drop the right one)
    gate = 10.0 * limit if not problem.estimate_focal and problem.model == "pinhole" and not robust else None
    # (a few pairs: every triplet's roots as well, so that a second pose fitting another subset as well is
    # found and the answer called ambiguous rather than ok)
    if tie is not None:
        seeds = []  # the poses that tie are found already, each at its minimum
    elif sampled is not None and problem.n_points > SMALL_PROBLEM_POINTS:
        seeds = []
    else:
        seeds = initial_seeds(problem, fu0, fv0, gate)
    if sampled is not None and problem.model != "pinhole":
        seeds.append((sampled.R, sampled.t))
    if prior2 is not None:
        seeds.append((prior2[:3, :3], prior2[:3, 3]))
    refine = _refiner(problem, fu0, fv0, huber, noise, floor)
    refined = [r for r in (refine(R, t) for R, t in distinct_seeds(seeds)) if r is not None]
    if tie is not None:
        # (the prior, if a copy of one of them, is refined to it and dropped as one by distinct_poses)
        refined = [*tie.minima, *refined]
    if sampled is not None and problem.model == "pinhole":
        # the sampler's own inliers are where its seed's consensus starts (one least-squares fit, usually)
        fit = consensus_refine(
            problem,
            sampled.R,
            sampled.t,
            fu0,
            fv0,
            inlier_threshold_px(noise),
            inliers=sampled.inliers,
            noise_floor_px=floor,
        )
        refined += [fit] if fit is not None else []
    best_rms = min((r.rms_px for r in refined), default=np.inf)
    if problem.n_points > SMALL_PROBLEM_POINTS and sampled is None and (best_rms > limit or robust):
        # A mis-click spoils the all-points seeds; triplets that avoid it still find the pose.
        refined += [r for r in (refine(R, t) for R, t in subset_p3p_seeds(problem, fu0, fv0)) if r is not None]
    if not refined:
        return _no_pose(
            problem, "no starting pose could be found for these picks (P3P/SQPnP found no pose in front of the camera)"
        )

    poses = distinct_poses(refined)
    if robust:  # judged by what they explain: two poses that each fit a different four of five pairs are ambiguous
        poses, scores = by_consensus(poses, inlier_threshold_px(noise))
    else:
        scores = [p.cost for p in poses]
    best = poses[0]
    close = [p for p, score in zip(poses, scores) if p.converged and score - scores[0] <= _AMBIGUITY_CHI2 * noise**2]
    if not close:
        close = [best]
    rivals = []
    if robust and problem.model == "pinhole":
        # with few pairs, the pair rejected is known only if no other one could be the mis-pick instead
        rivals = distinct_poses(
            [
                r
                for r in rival_consensus(problem, close[0], noise) + other_minima(problem, close[0], noise, solve_pose)
                if not any(same_pose(r.obj2cam, c.obj2cam) for c in close)
            ]
        )
        close += rivals
    distances = [None if prior2 is None else _distance_to_prior_mm(p, prior2, intrinsics) for p in close]
    rank = sorted(
        range(len(close)), key=lambda i: (distances[i], close[i].cost) if prior2 is not None else (close[i].cost,)
    )
    ranked = [close[i] for i in rank]
    candidates = tuple(PoseCandidate(p.obj2cam, p.fu, p.fv, p.rms_px, distances[i]) for p, i in zip(ranked, rank))
    if tie is not None and tie.best is not None and ranked[0] is tie.minima[0] and not rivals:
        # the fast path summarised this minimum already: the same figures finish_solution would take again
        solution = stated_with_candidates(tie.best, candidates)
    else:
        solution = finish_solution(problem, ranked[0], candidates, sigma_px=sigma_px, limit_px=limit, huber_px=huber)
    # name the pairs: the operator re-picks those, not every point (a second minimum of the same pairs names none)
    suspects = sorted({int(i) for r in rivals for i in np.flatnonzero(r.inliers != close[0].inliers)})
    if rivals and solution.status is SolveStatus.AMBIGUOUS and suspects:
        solution = replace(
            solution,
            reason=f"{points_label(suspects)}: any one of them could be the pick that is off (leaving out each, the "
            "others fit as well); "
            "pick them again or add a point",
        )
    return solution


def _confidence_order(confidence: ArrayLike | None, n: int) -> np.ndarray | None:
    """The pairs' indices (n,) most confident first, or ``None`` without confidences."""
    if confidence is None:
        return None
    c = np.asarray(confidence, dtype=float).reshape(-1)
    if c.shape != (n,) or not np.all(np.isfinite(c)):
        raise ValueError(f"confidence: one finite number per pair ({n}), got {c.shape[0]}")
    return np.argsort(-c, kind="stable")


def _refiner(problem: PoseProblem, fu: float, fv: float, huber: float | None, noise: float, floor: float):
    """How each seed is refined: least squares, or when robust, on the pairs it agrees with (pinhole; the
    paper's model keeps Huber's loss)."""
    if huber is not None and problem.model == "pinhole":
        return lambda R, t: consensus_refine(problem, R, t, fu, fv, inlier_threshold_px(noise), noise_floor_px=floor)
    return lambda R, t: refine_seed(problem, R, t, fu, fv, huber)


def refine_pose(
    points_3d: ArrayLike,
    points_2d: ArrayLike,
    intrinsics: Intrinsics,
    start_obj2cam: ArrayLike,
    *,
    estimate_focal: bool = False,
    model: str = "pinhole",
    sigma_px: float | None = None,
    robust: bool = False,
    max_rms_px: float | None = None,
    damped: bool = True,
    max_iterations: int = 100,
) -> PoseSolution:
    """Newton iterations from ``start_obj2cam`` (4, 4) only, as in the paper: no global seeds.

    Finds the pose nearest the start, silently ignoring any other pose that fits; use
    :func:`solve_pose` unless reproducing the paper or measuring convergence.
    ``damped=False`` takes full Newton steps like the paper's program.
    """
    problem, start = _prepare(points_3d, points_2d, intrinsics, start_obj2cam, estimate_focal, model, sigma_px)
    if start is None:
        raise ValueError("refine_pose needs a starting pose (start_obj2cam)")
    noise = noise_px(sigma_px)
    limit = 5.0 * noise if max_rms_px is None else float(max_rms_px)
    huber = 2.0 * noise if robust else None
    r = refine_seed(
        problem,
        start[:3, :3],
        start[:3, 3],
        intrinsics.fu,
        intrinsics.fv,
        huber,
        damped=damped,
        max_iterations=max_iterations,
    )
    if r is None:
        return _no_pose(problem, "the starting pose puts points behind the camera")
    candidate = PoseCandidate(r.obj2cam, r.fu, r.fv, r.rms_px)
    return finish_solution(problem, r, (candidate,), sigma_px=sigma_px, limit_px=limit, huber_px=huber)


def _no_pose(problem: PoseProblem, reason: str) -> PoseSolution:
    n = problem.n_points
    return PoseSolution(
        status=SolveStatus.FAILED,
        obj2cam=np.full((4, 4), np.nan),
        fu=problem.intrinsics.fu,
        fv=problem.intrinsics.fv,
        model=problem.model,
        iterations=0,
        residuals_px=np.full((n, 2), np.nan),
        uncertainty=None,
        leave_one_out_px=np.full(n, np.nan),
        outliers=np.zeros(n, dtype=bool),
        candidates=(),
        reason=reason,
    )


__all__ = ["solve_pose", "refine_pose", "DEFAULT_SIGMA_PX", "pose_matrix"]


def _solve_distinct(first: np.ndarray, points_3d, points_2d, intrinsics, **options) -> PoseSolution:
    """Solve on each distinct pair once; report on every pair given (a repeat shares its first's
    residual, leave-one-out and outlier flag), the messages numbering the pairs as given."""
    keep = np.flatnonzero(first == np.arange(len(first)))
    place = np.searchsorted(keep, first)  # each pair's row in the distinct set
    confidence = options.pop("confidence")
    if confidence is not None:
        confidence = np.asarray(confidence, dtype=float).reshape(-1)
        if confidence.shape == first.shape:
            confidence = confidence[keep]
    with named_points_as_given(keep):
        solution = solve_pose(
            np.asarray(points_3d, float)[keep],
            np.asarray(points_2d, float)[keep],
            intrinsics,
            confidence=confidence,
            **options,
        )
    repeats = np.flatnonzero(first != np.arange(len(first)))
    shown = ", ".join(f"{point_label(int(r))} = {point_label(int(first[r]))}" for r in repeats[:5]) + (
        f" and {len(repeats) - 5} more" if len(repeats) > 5 else ""
    )
    note = (
        f"{len(repeats)} pair{'s' if len(repeats) > 1 else ''} given again (the same 3D point at the same pixel), "
        f"each counted once: {shown}"
    )
    return replace(
        solution,
        residuals_px=solution.residuals_px[place],
        leave_one_out_px=solution.leave_one_out_px[place],
        outliers=solution.outliers[place],
        warnings=(note, *solution.warnings),
    )
