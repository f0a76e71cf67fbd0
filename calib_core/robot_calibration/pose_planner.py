"""Poses for a robot calibration: reachable, collision-free, the whole board in view, spread to
determine the parameters best.

Candidates come from :func:`~calib_core.vision.board_placement.board_view_joints` (the camera aimed
at the board from directions within 30 deg of its normal, rolled about its axis, 420-600 mm away,
and turned up to 15 deg off it so the board reaches the image's corners),
each checked against the joint limits, the cell's collision bodies and the image's edges with the
nominal model. Of those, poses are chosen greedily to maximise the determinant of the
identification's information matrix (D-optimal design, with the board's placement as a nuisance):
the pose that adds most to what the set determines comes next. The information includes the
intrinsics and the lens distortion, since the same views calibrate the camera: a set whose corners
stay in the image's middle leaves the distortion at its edges a guess, and a component seen there
later is measured through that guess.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, concat, invert
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.identification import IdentificationProblem
from calib_core.robot_calibration.observations import PoseView
from calib_core.vision.board_placement import board_view_joints

EDGE_MARGIN_PX = 30.0
OFF_CENTRE_DEG = 15.0


@dataclass(frozen=True)
class PosePlan:
    """``joints_deg``: the chosen poses in the order to visit them; ``candidates`` how many were
    generated, ``rejected`` why the others were left (reason -> count); ``log_det`` the chosen set's
    information (higher is better); ``cell_views`` (component, joints deg) poses that view the
    surveyed components (:func:`~calib_core.robot_calibration.cell_views.cell_view_joints`), visited
    after the board's, which tie the robot to the cell."""

    joints_deg: list[np.ndarray]
    candidates: int
    rejected: dict[str, int]
    log_det: float
    cell_views: list[tuple[str, np.ndarray]] = field(default_factory=list)


def _sees_board(robot: RobotModel, intrinsics: Intrinsics, q, board2base, corners) -> bool:
    px = project(apply(concat(board2base, invert(robot.fk(q, "camera"))), corners), intrinsics)
    return bool(np.all(np.isfinite(px)) and np.all(intrinsics.contains(px, EDGE_MARGIN_PX)))


def plan_poses(
    robot: RobotModel,
    intrinsics: Intrinsics,
    spec,
    board2base: np.ndarray,
    n: int = 40,
    *,
    start_deg=None,
    collisions=None,
    candidates: int = 160,
    seed: int = 0,
) -> PosePlan:
    """``n`` poses (deg/mm) viewing the board at ``board2base`` (4, 4) mm; ``collisions`` a
    :class:`~calib_core.robot.collision.CollisionWorld` (``None``: not checked)."""
    start = np.zeros(robot.n_joints) if start_deg is None else np.asarray(start_deg, dtype=float)
    corners = spec.corners_mm()
    pool = board_view_joints(robot, start, spec, board2base, candidates, seed, off_centre_deg=OFF_CENTRE_DEG)
    rejected: dict[str, int] = {}
    kept = []
    for q in pool:
        if not np.all(robot.within_limits(q, 1.0)):
            rejected["near a joint limit"] = rejected.get("near a joint limit", 0) + 1
        elif not _sees_board(robot, intrinsics, q, board2base, corners):
            rejected["the board not wholly in view"] = rejected.get("the board not wholly in view", 0) + 1
        elif collisions is not None and collisions.check(q):
            rejected["a collision"] = rejected.get("a collision", 0) + 1
        else:
            kept.append(q)
    if not kept:
        return PosePlan([], len(pool), rejected, float("-inf"))
    # Each candidate's block of the identification Jacobian at the nominal model, board as nuisance.
    views = [
        PoseView(
            f"c{k}", q, corners, project(apply(concat(board2base, invert(robot.fk(q, "camera"))), corners), intrinsics)
        )
        for k, q in enumerate(kept)
    ]
    problem = IdentificationProblem(robot, intrinsics, views, "camera", True)
    problem.board0 = board2base
    J, Jb = problem.jacobian(np.zeros(problem.size), np.zeros(6), list(range(problem.size)))
    rows = 2 * len(corners)
    blocks = [np.hstack([J[k * rows : (k + 1) * rows], Jb[k * rows : (k + 1) * rows]]) for k in range(len(kept))]
    info_blocks = [B.T @ B for B in blocks]
    p = J.shape[1]
    total = sum(info_blocks)
    ridge = 1e-9 * np.trace(total) / total.shape[0]

    def score(M):
        # Information about the robot's parameters once the board's placement is fitted too (Schur).
        A, Bm, C = M[:p, :p], M[:p, p:], M[p:, p:]
        S = A - Bm @ np.linalg.solve(C + ridge * np.eye(6), Bm.T)
        sign, logdet = np.linalg.slogdet(S + ridge * np.eye(p))
        return logdet

    chosen: list[int] = []
    M = np.zeros_like(total)
    for _ in range(min(n, len(kept))):
        best, best_score = None, -np.inf
        for k in range(len(kept)):
            if k in chosen:
                continue
            s = score(M + info_blocks[k])
            if s > best_score:
                best, best_score = k, s
        chosen.append(best)
        M = M + info_blocks[best]
    # Visit in an order that keeps the moves short: nearest next from the start.
    order, at, left = [], start, list(chosen)
    while left:
        k = min(left, key=lambda i: float(np.max(np.abs(kept[i] - at))))
        order.append(k)
        at = kept[k]
        left.remove(k)
    return PosePlan([kept[k] for k in order], len(pool), rejected, float(score(M)))
