"""The common cases in one compiled call: four or more pairs (up to eight on a plane), known focal lengths, pinhole
model, no robust loss (six and more off a plane seeded by a DLT, four and five, and a plane's up to eight, by P3P
over the largest triangles). Returns ``None`` whenever the full search is needed (no seed, no convergence, a fit
worse than the limit, a pair that may be a mis-pick), and a :class:`Tie` when for a few pairs a second pose fits
about as well (a plane's mirror pose): the full search ranks the poses found by the prior and reports them, without
seeking them again."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.solver.initialisation import MAX_SUBSETS, P3P_SEEDED_UP_TO
from calib_core.solver.finish import noise_px, operator_warnings
from calib_core.solver.candidates import SAME_POSE_COS, SAME_POSE_REL, RefinedPose
from calib_core.solver.kernels.fast_path import dlt_newton_summary, p3p_newton_summary
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT
from calib_core.solver.misfit import FALSE_FLAG_PER_SOLVE, OWN_SCALE_MIN_DOF, fisher_quantile
from calib_core.solver.problem import PoseProblem
from calib_core.solver.refine import NewtonResult
from calib_core.solver.solution import PoseCandidate, PoseSolution, SolveStatus
from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX, uncertainty_from

_MAX_ITERATIONS = 100
SEEDED_BY_DLT = 6


@dataclass(frozen=True)
class Tie:
    """Two or more distinct poses that fit the pairs about as well (within the ambiguity margin), each refined to its
    own least-squares minimum, the best first. Every such minimum has a P3P root of each triplet near it, and the
    fast path refined the roots of the full search's triplets: it would find these same poses."""

    minima: tuple[RefinedPose, ...]
    best: PoseSolution | None = None
    """The best minimum's solution as the fast path states it (its own summary: uncertainty, leave-one-out, warnings;
    alone, status ``ok``), for the full search to state it ambiguous when it ranks that minimum first; ``None`` when
    a pair may be a mis-pick there (the full search then judges it)."""


def _at_minimum(
    problem: PoseProblem, obj2cam: np.ndarray, iterations: int, outcome: int, r: np.ndarray, J: np.ndarray
) -> RefinedPose:
    """A minimum the fast path refined (converged), as the full search's refinement gives it, with every pair's
    residual ``r`` (n, 2) and Jacobian ``J`` (n, 2, 6) there (the kernel's, at that minimum)."""
    intr = problem.intrinsics
    R, t = obj2cam[:3, :3].copy(), obj2cam[:3, 3].copy()
    cost = float(np.sum(r**2))
    newton = NewtonResult(R, t, intr.fu, intr.fv, r, J, iterations, outcome)
    return RefinedPose(obj2cam, intr.fu, intr.fv, cost, float(np.sqrt(cost / problem.n_points)), True, newton)


def applies(problem: PoseProblem, robust: bool) -> bool:
    return (
        problem.n_points >= 4
        and (not problem.coplanar or problem.n_points <= P3P_SEEDED_UP_TO)
        and not problem.estimate_focal
        and problem.model == "pinhole"
        and not robust
    )


def fast_solve(
    problem: PoseProblem, sigma_px: float | None, limit_px: float, ambiguity_chi2: float = 9.0
) -> PoseSolution | Tie | None:
    """Solve ``problem`` through the compiled fast path, or ``None`` to fall back. For a few pairs (P3P's seeds),
    a second minimum costing within ``ambiguity_chi2`` noise variances of the best is an ambiguity the full search
    reports (the same rule): the minima are returned as a :class:`Tie` when the best fits within the limit."""
    intr = problem.intrinsics
    n = problem.n_points
    sigma = -1.0 if sigma_px is None else float(sigma_px)
    noise = noise_px(sigma_px)
    # The full path's own mis-pick test on the fit (from its hat matrix, no further solve): a pair it would flag sends
    # the problem there. (A bound by the leave-one-out misses alone sent two clean four-pair solves in three there:
    # with little redundancy they exceed the statistic many times.)
    fisher = 2.0 * fisher_quantile(n, 2 * n - 8) if 2 * n - 8 >= OWN_SCALE_MIN_DOF else np.inf
    misfit_test = (noise, fisher, float(OWN_SCALE_MIN_DOF), FALSE_FLAG_PER_SOLVE)
    common = (intr.fu, intr.fv, intr.cx, intr.cy, problem.distortion, _MAX_ITERATIONS, sigma, DEFAULT_SIGMA_PX)
    out = None
    if n >= SEEDED_BY_DLT and not problem.coplanar:  # (a plane's points leave the DLT's 12 unknowns undetermined)
        out = dlt_newton_summary(problem.points_3d, problem.points_2d, *common, misfit_test)
    if out is None and n <= P3P_SEEDED_UP_TO:
        # (six to eight pairs whose DLT found no seed, a noisy near-minimal DLT, take the triplets' roots as four do)
        # A P3P root that puts all the pairs more than ten times the limit off is refuted by them;
        # every minimum that fits them has a root of each triplet near it.
        out = p3p_newton_summary(
            problem.points_3d,
            problem.points_2d,
            *common,
            misfit_test,
            10.0 * limit_px,
            ambiguity_chi2 * noise**2,
            SAME_POSE_COS,
            SAME_POSE_REL,
            MAX_SUBSETS,
        )
    if out is None:
        return None
    obj2cam, r, cov, cov_c, loo, scalars, rivals, rival_fits, minima_r, minima_J = out
    iterations, outcome, rms, sigma, source, condition, misfit = scalars
    if int(outcome) not in (CONVERGED, EXACT_FIT) or not rms <= limit_px:
        return None
    solution = None if misfit != 0.0 else _solution(problem, obj2cam, r, cov, cov_c, loo, scalars, noise)
    if len(rivals):
        fits = ((obj2cam, iterations, outcome), *((pose, *fit) for pose, fit in zip(rivals, rival_fits)))
        return Tie(
            tuple(
                _at_minimum(problem, pose, int(its), int(code), minima_r[k], minima_J[k])
                for k, (pose, its, code) in enumerate(fits)
            ),
            solution,
        )
    return solution


def _solution(
    problem: PoseProblem,
    obj2cam: np.ndarray,
    r: np.ndarray,
    cov: np.ndarray,
    cov_c: np.ndarray,
    loo: np.ndarray,
    scalars: np.ndarray,
    noise: float,
) -> PoseSolution:
    """The fast path's fit, summarised by the kernel, as an ``ok`` solution with itself the only candidate."""
    intr = problem.intrinsics
    iterations, _, rms, sigma, source, condition, _ = scalars
    n = problem.n_points
    return PoseSolution(
        status=SolveStatus.OK,
        obj2cam=obj2cam,
        fu=intr.fu,
        fv=intr.fv,
        model="pinhole",
        iterations=int(iterations),
        residuals_px=r,
        uncertainty=uncertainty_from(cov, cov_c, sigma, int(source), condition),
        leave_one_out_px=loo,
        outliers=np.zeros(n, dtype=bool),
        candidates=(PoseCandidate(obj2cam, intr.fu, intr.fv, float(rms)),),
        warnings=tuple(operator_warnings(problem, condition, noise)),
    )
