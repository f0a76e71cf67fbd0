"""Choosing among refined poses when some pairs may be wrong: by consensus, not by least squares.

Least squares (and Huber's loss, which grows linearly) prefer a pose that spreads one mis-click's
100 px over several good pairs: with 5 pairs and one 50-200 px off, the robust solve once fitted
three pairs exactly, flagged two good ones and called a pose up to 550 mm wrong ``ok`` in 64 of 200
scenes. RANSAC's MSAC score caps each pair's squared error at the inlier threshold, so a pose is
judged by how many pairs it explains and how well: the pose that fits the four good pairs wins.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from calib_core.solver.candidates import RefinedPose, refine_seed
from calib_core.solver.misfit import admissible
from calib_core.solver.problem import PoseProblem
from calib_core.solver.kernels.subset_fit import FITTED, fit_subset_rounds
from calib_core.solver.refine import NewtonResult, residuals_and_jacobian
from calib_core.solver.solution import PoseSolution, pose_matrix

_MAX_ITERATIONS = 100

INLIER_SIGMAS = 4.0
"""A pair is an inlier within this many times the pick noise (the outlier flag's threshold)."""


def inlier_threshold_px(noise_px: float) -> float:
    return INLIER_SIGMAS * float(noise_px)


def msac_score(residuals_px: np.ndarray, threshold_px: float) -> float:
    """Sum over pairs of min(e^2, threshold^2), px^2: ``residuals_px`` (n, 2)."""
    e2 = np.sum(np.square(np.asarray(residuals_px, dtype=float)), axis=1)
    return float(np.sum(np.minimum(e2, threshold_px**2)))


def by_consensus(poses: list[RefinedPose], threshold_px: float) -> tuple[list[RefinedPose], list[float]]:
    """``poses`` ordered by MSAC score at their own residuals, converged first (stable otherwise), and
    their scores in that order."""
    scored = sorted(((not p.converged, msac_score(p.newton.residuals, threshold_px), k) for k, p in enumerate(poses)))
    return [poses[k] for _, _, k in scored], [score for _, score, _ in scored]


def consensus_refine(
    problem: PoseProblem,
    R: np.ndarray,
    t_mm: np.ndarray,
    fu: float,
    fv: float,
    threshold_px: float,
    *,
    rounds: int = 4,
    inliers: np.ndarray | None = None,
    noise_floor_px: float | None = None,
) -> RefinedPose | None:
    """Local optimisation as LO-RANSAC does it, in place of Huber's loss (which, with few pairs, walks from
    the right pose to one that spreads a mis-click over good pairs: 170 mm off from a right seed): the pairs
    within reach of the pose, least squares on those alone, again until the set stays. The result's
    residuals and Jacobian are over *every* pair, at the inliers' pose. ``None`` when fewer pairs than a
    pose needs agree. Pinhole model. ``inliers`` (n,) bool: the set to start from (a sampler's), instead of
    the pairs near the seed. ``noise_floor_px`` the noise model a left-out pair is judged against for
    admission (default: the threshold's)."""
    minimal = 4 if problem.estimate_focal else 3
    n, p = problem.n_points, problem.n_params
    R = np.array(R, dtype=float, order="C")  # (a transposed rotation is F-ordered: another compiled signature)
    t = np.array(t_mm, dtype=float).reshape(3)
    f = np.array([fu, fv], dtype=float)
    if inliers is None:
        r, _, _ = residuals_and_jacobian(problem, R, t, fu, fv)
        inliers = np.linalg.norm(r, axis=1) < 3.0 * threshold_px  # a seed from three pairs is only near the pose
    inliers = np.array(inliers, dtype=np.bool_)  # (the rounds update it)
    r, J = np.empty((n, 2)), np.empty((n, 2, p))
    fit = _fit_rounds(problem, R, t, f, inliers, threshold_px, rounds, minimal, r, J)
    if fit is None or not np.all(np.isfinite(r)):
        return None
    iterations, outcome = fit
    # A good pick just beyond the threshold (a 2-D Gaussian's tail) is judged as the misfit test judges picks:
    # by how far the inliers' pose misses it against that prediction's spread. Admitted pairs join the fit.
    floor = threshold_px / INLIER_SIGMAS if noise_floor_px is None else noise_floor_px
    for _ in range(rounds):
        admit = admissible(J, r, inliers, p, floor)
        if not admit.any():
            break
        inliers = inliers | admit
        R2, t2, f2, r2, J2 = R.copy(), t.copy(), f.copy(), np.empty_like(r), np.empty_like(J)
        again = _fit_rounds(problem, R2, t2, f2, inliers.copy(), threshold_px, 1, minimal, r2, J2)
        if again is None:
            break
        (iterations, outcome), R, t, f, r, J = again, R2, t2, f2, r2, J2
    newton = NewtonResult(R, t, float(f[0]), float(f[1]), r, J, int(iterations), int(outcome))
    cost = float(np.sum(r**2))
    return RefinedPose(
        pose_matrix(R, t),
        newton.fu,
        newton.fv,
        cost,
        float(np.sqrt(cost / n)),
        newton.converged,
        newton,
        inliers.copy(),
    )


def _fit_rounds(problem: PoseProblem, R, t, f, inliers, threshold_px, rounds, minimal, r, J) -> tuple[int, int] | None:
    """:func:`~calib_core.solver.kernels.subset_fit.fit_subset_rounds` on the problem (the state, ``inliers``, ``r``
    and ``J`` updated in place): the last fit's ``(iterations, outcome)``, or ``None`` when no pose came of it."""
    intr = problem.intrinsics
    code, iterations, outcome = fit_subset_rounds(
        problem.points_3d,
        problem.points_2d,
        R,
        t,
        f,
        intr.cx,
        intr.cy,
        problem.distortion,
        problem.estimate_focal,
        inliers,
        float(threshold_px),
        rounds,
        _MAX_ITERATIONS,
        minimal,
        r,
        J,
    )
    if code != FITTED or not (np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
        return None
    return int(iterations), int(outcome)


RIVAL_CHECK_POINTS = 10
"""Up to this many pairs, a consensus that rejected pairs is checked for a rival of the same size."""

_CONSISTENT_QUANTILE = 0.999


def _own_minimum(sub: PoseProblem, chosen: RefinedPose) -> RefinedPose | None:
    """The least-squares pose of the pairs of ``sub`` alone, seeded by P3P over its triplets (compiled), or None."""
    from calib_core.solver.initialisation import MAX_SUBSETS
    from calib_core.solver.kernels.fast_path import p3p_newton_summary
    from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX

    if sub.n_points < 4 or sub.coplanar:
        return None
    intr = sub.intrinsics
    out = p3p_newton_summary(
        sub.points_3d,
        sub.points_2d,
        chosen.fu,
        chosen.fv,
        intr.cx,
        intr.cy,
        sub.distortion,
        100,
        -1.0,
        DEFAULT_SIGMA_PX,
        (1.0, np.inf, 1e9, 1e-3),  # (its mis-pick test is not asked here)
        1e9,
        -1.0,
        1.0,
        0.0,
        MAX_SUBSETS,
    )
    if out is None:
        return None
    obj2cam = out[0]
    return refine_seed(sub, obj2cam[:3, :3].copy(), obj2cam[:3, 3].copy(), chosen.fu, chosen.fv, None)


def rival_consensus(problem: PoseProblem, chosen: RefinedPose, noise_px: float) -> list[RefinedPose]:
    """Other poses that explain as many pairs as ``chosen`` does, each pair within the noise: ``chosen``'s
    inliers with one of them swapped for one it rejected, fitted by least squares and consistent (squared
    residuals over ``noise_px``^2 within chi-square's 99.9 % for their degrees of freedom). With few pairs a
    least-squares pose can absorb a 5-10 px mis-pick into four others while a good pair is the one left out
    (5 pairs: a pose 10 mm wrong called ok): an outlier is known only when no swap explains the pairs as well.
    Empty beyond :data:`RIVAL_CHECK_POINTS` pairs or when nothing was rejected. Pinhole model."""
    from scipy.special import chdtri  # chi-square's upper-tail quantile (scipy.stats: half a second to import)

    if chosen.inliers is None or problem.n_points > RIVAL_CHECK_POINTS or chosen.inliers.all():
        return []
    dof = 2 * int(chosen.inliers.sum()) - problem.n_params
    if dof <= 0:
        return []
    limit = float(chdtri(dof, 1.0 - _CONSISTENT_QUANTILE)) * float(noise_px) ** 2
    rivals: list[RefinedPose] = []
    for out in np.flatnonzero(~chosen.inliers):
        for swap in np.flatnonzero(chosen.inliers):
            subset = chosen.inliers.copy()
            subset[swap], subset[out] = False, True
            idx = np.flatnonzero(subset)
            sub = replace(
                problem,
                points_3d=problem.points_3d[idx],
                points_2d=problem.points_2d[idx],
                off_image=(),
                repeated_3d=(),
            )
            fit = refine_seed(sub, chosen.newton.R, chosen.newton.t, chosen.fu, chosen.fv, None)
            if fit is None or not fit.converged or fit.cost > limit:
                # from the chosen pose the swapped set's own minimum may be out of reach (a rival tens of mm away):
                # its triplets' P3P roots find it
                fit = _own_minimum(sub, chosen)
            if fit is None or not fit.converged or fit.cost > limit:
                continue
            r, J, _ = residuals_and_jacobian(problem, fit.newton.R, fit.newton.t, fit.fu, fit.fv)
            newton = NewtonResult(
                fit.newton.R, fit.newton.t, fit.fu, fit.fv, r, J, fit.newton.iterations, fit.newton.outcome
            )
            cost = float(np.sum(r**2))
            rivals.append(
                RefinedPose(
                    fit.obj2cam, fit.fu, fit.fv, cost, float(np.sqrt(cost / problem.n_points)), True, newton, subset
                )
            )
    return rivals


def other_minima(
    problem: PoseProblem, chosen: RefinedPose, noise_px: float, solve_plain: Callable[..., PoseSolution]
) -> list[RefinedPose]:
    """Other poses that fit ``chosen``'s own consensus about as well: its pairs alone, solved as a plain problem, which
    seeds every triplet's P3P roots and calls two minima within the noise ambiguous. With four or five agreeing pairs a
    second minimum can fit them as well (4 pairs: two poses 32 mm apart, both at 0.35 px) while the sampler found only
    one. Each returned with its residuals over every pair and ``chosen``'s inliers; empty when the consensus has
    fewer than four or more than :data:`RIVAL_CHECK_POINTS` pairs, or one pose. Pinhole model, focal lengths known.
    ``solve_plain(points_3d, points_2d, intrinsics, sigma_px=...)``: the plain solve (the caller's: the solver that
    calls this check is the one it runs again)."""
    from calib_core.solver.solution import SolveStatus

    if chosen.inliers is None or problem.estimate_focal or problem.model != "pinhole":
        return []
    idx = np.flatnonzero(chosen.inliers)
    if not 4 <= len(idx) <= RIVAL_CHECK_POINTS:
        return []
    intr = problem.intrinsics
    own = solve_plain(
        problem.points_3d[idx], problem.points_2d[idx], intr.with_focal(chosen.fu, chosen.fv), sigma_px=noise_px
    )
    if own.status is not SolveStatus.AMBIGUOUS:
        return []
    out = []
    for c in own.candidates:
        R, t = c.obj2cam[:3, :3].copy(), c.obj2cam[:3, 3].copy()
        r, J, _ = residuals_and_jacobian(problem, R, t, chosen.fu, chosen.fv)
        cost = float(np.sum(r**2))
        newton = NewtonResult(R, t, chosen.fu, chosen.fv, r, J, 0, 0)
        out.append(
            RefinedPose(
                c.obj2cam,
                chosen.fu,
                chosen.fv,
                cost,
                float(np.sqrt(cost / problem.n_points)),
                True,
                newton,
                chosen.inliers.copy(),
            )
        )
    return out
