"""Refining seeds into candidate poses and keeping the distinct ones.

The paper's model is refined in its own parameters and read back as a metric pose, so
both models yield the same kind of candidate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.solver.paper_model import paper_shift_from_pose, pose_translation_from_paper_shift
from calib_core.solver.problem import PoseProblem
from calib_core.solver.refine import NewtonResult, run_newton
from calib_core.solver.solution import pose_matrix

# Two refined poses closer than this are the same minimum reached from different seeds. (In a flat valley, four to
# eight points on a plane, two refinements of one minimum stop up to a few 1e-4 deg apart: a tighter test called them
# two poses and the solve ambiguous. A thousandth of a degree is far below any pose's 1-sigma.) The turn is what
# tells two minima apart; their places need only be within a hundredth of the distance (5 mm at 500 mm), the bound
# this test has always had.
SAME_POSE_DEG = 1e-3
SAME_POSE_COS = float(np.cos(np.radians(SAME_POSE_DEG)))
SAME_POSE_REL = 1e-2


@dataclass(frozen=True)
class RefinedPose:
    """A seed after refinement. ``obj2cam`` (4, 4) mm (for the paper's model: its ``h`` read
    as a metric pose); ``cost`` the sum of squared residual lengths, px^2; ``newton`` the raw
    iteration result (the paper's model keeps its ``(d_x, d_y, d_z)`` in ``newton.t``)."""

    obj2cam: np.ndarray
    fu: float
    fv: float
    cost: float
    rms_px: float
    converged: bool
    newton: NewtonResult
    inliers: np.ndarray | None = None
    """(n,) bool: the pairs it was fitted to by least squares (a consensus refinement), or ``None`` (all)."""


def refine_seed(
    problem: PoseProblem,
    R: np.ndarray,
    t_mm: np.ndarray,
    fu: float,
    fv: float,
    huber_px: float | None,
    *,
    damped: bool = True,
    max_iterations: int = 100,
) -> RefinedPose | None:
    """Refine one seed pose in the problem's model; ``None`` if the seed is unusable."""
    paper = problem.model == "paper"
    start_t = paper_shift_from_pose(t_mm, problem.intrinsics, fu, fv) if paper else t_mm
    result = run_newton(problem, R, start_t, fu, fv, huber_px=huber_px, damped=damped, max_iterations=max_iterations)
    if result.iterations == 0 and not result.converged:
        return None
    if not np.all(np.isfinite(result.residuals)):
        return None
    t_f = pose_translation_from_paper_shift(result.t, problem.intrinsics, result.fu, result.fv) if paper else result.t
    cost = float(np.sum(result.residuals**2))
    return RefinedPose(
        pose_matrix(result.R, t_f),
        result.fu,
        result.fv,
        cost,
        float(np.sqrt(cost / problem.n_points)),
        result.converged,
        result,
    )


def same_pose(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two ``obj2cam`` poses are the same minimum (to round-off of the solver)."""
    scale = max(float(np.linalg.norm(a[:3, 3])), 1.0)
    if np.linalg.norm(a[:3, 3] - b[:3, 3]) > SAME_POSE_REL * scale:
        return False
    # cos of the relative angle from the trace: scipy's conversion costs more than the solve at small N
    cos_angle = (float(np.sum(a[:3, :3] * b[:3, :3])) - 1.0) / 2.0
    return cos_angle >= SAME_POSE_COS


def distinct_poses(refined: list[RefinedPose]) -> list[RefinedPose]:
    """The distinct refined poses, lowest cost first (converged before unconverged at equal cost)."""
    ordered = sorted(refined, key=lambda r: (not r.converged, r.cost))
    ordered = sorted(ordered, key=lambda r: r.cost if r.converged else np.inf)
    kept: list[RefinedPose] = []
    for r in ordered:
        if not any(same_pose(r.obj2cam, k.obj2cam) for k in kept):
            kept.append(r)
    return kept
