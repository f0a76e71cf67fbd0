"""Inverse kinematics: joints that put a frame at a target pose, closest to the current joints.

Damped least squares on the 6D error (position in mm, rotation as a rotation vector in rad
weighted by a length), with joint limits enforced by clamping, from several seeds: the
current joints first, then spread-out configurations. Of the seeds that converge, the one
closest to the current joints wins, so the robot never flips its wrist or elbow needlessly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.transform import Rotation

from calib_core.frames import check_transform
from calib_core.robot.errors import UnreachableTargetError
from calib_core.robot.model import RobotModel

POSITION_TOL_MM = 1e-4
ROTATION_TOL_DEG = 1e-5
# A rotation error of 1 rad weighs like a position error of this many mm.
_ROTATION_WEIGHT_MM = 200.0
_DAMPING = 1.0
_MAX_STEP_DEG = 20.0


@dataclass(frozen=True)
class IKSolution:
    """Joints ``q_deg`` (n,) deg reaching the target to ``position_error_mm`` and
    ``rotation_error_deg``; ``iterations`` of the winning seed, ``seeds_converged`` of ``seeds_tried``."""

    q_deg: np.ndarray
    position_error_mm: float
    rotation_error_deg: float
    iterations: int
    seeds_converged: int
    seeds_tried: int


def _pose_error(robot: RobotModel, q_deg: np.ndarray, target: np.ndarray, frame: str) -> np.ndarray:
    T = robot.fk(q_deg, frame)
    e_p = target[:3, 3] - T[:3, 3]
    e_w = Rotation.from_matrix(target[:3, :3] @ T[:3, :3].T).as_rotvec()
    return np.concatenate([e_p, e_w])


def _descend(
    robot: RobotModel, q0: np.ndarray, target: np.ndarray, frame: str, max_iterations: int
) -> tuple[np.ndarray, np.ndarray, int]:
    lo, hi = robot.lower_limits_deg, robot.upper_limits_deg
    q = np.clip(q0, lo, hi)
    W = np.diag([1.0, 1.0, 1.0, _ROTATION_WEIGHT_MM, _ROTATION_WEIGHT_MM, _ROTATION_WEIGHT_MM])
    e = _pose_error(robot, q, target, frame)
    for iteration in range(1, max_iterations + 1):
        if np.linalg.norm(e[:3]) < POSITION_TOL_MM and np.degrees(np.linalg.norm(e[3:])) < ROTATION_TOL_DEG:
            return q, e, iteration - 1
        J = W @ robot.jacobian(q, frame)
        ew = W @ e
        dq = J.T @ np.linalg.solve(J @ J.T + _DAMPING**2 * np.eye(6), ew)
        dq_deg = np.degrees(dq)
        largest = np.max(np.abs(dq_deg))
        if largest > _MAX_STEP_DEG:
            dq_deg *= _MAX_STEP_DEG / largest
        q = np.clip(q + dq_deg, lo, hi)
        e = _pose_error(robot, q, target, frame)
    return q, e, max_iterations


def _seeds(robot: RobotModel, q_current: np.ndarray, extra: int, rng: np.random.Generator) -> list[np.ndarray]:
    lo, hi = robot.lower_limits_deg, robot.upper_limits_deg
    seeds = [q_current]
    mid = np.clip(np.zeros_like(q_current), lo, hi)
    seeds.append(mid)
    for _ in range(extra):
        seeds.append(rng.uniform(np.maximum(lo, -150.0), np.minimum(hi, 150.0)))
    return seeds


def solve_ik(
    robot: RobotModel,
    target2base: ArrayLike,
    q_current_deg: ArrayLike | None = None,
    *,
    frame: str = "tcp",
    extra_seeds: int = 12,
    max_iterations: int = 200,
    seed: int = 0,
) -> IKSolution:
    """Joints (deg) that put ``frame`` at ``target2base`` (4, 4, mm), closest to ``q_current_deg``.

    Raises :class:`UnreachableTargetError` (with the closest attempt) when no seed converges
    within the joint limits, and :class:`UnknownFrameError` for a frame the robot lacks.
    """
    target = check_transform(target2base, name="IK target")
    robot.frame_id(frame)
    q_current = robot.check_joints(np.zeros(robot.n_joints) if q_current_deg is None else q_current_deg)
    rng = np.random.default_rng(seed)
    found: list[tuple[np.ndarray, np.ndarray, int]] = []
    best_miss = (np.inf, np.inf)
    tried = 0
    for q0 in _seeds(robot, q_current, extra_seeds, rng):
        tried += 1
        q, e, iterations = _descend(robot, q0, target, frame, max_iterations)
        pos, rot = float(np.linalg.norm(e[:3])), float(np.degrees(np.linalg.norm(e[3:])))
        if pos < POSITION_TOL_MM and rot < ROTATION_TOL_DEG:
            found.append((q, e, iterations))
            # The current joints converging is the usual case (small moves): no need to look further.
            if tried == 1:
                break
        elif pos + rot < sum(best_miss):
            best_miss = (pos, rot)
    if not found:
        raise UnreachableTargetError(
            f"the {frame} cannot reach the target within the joint limits (closest: {best_miss[0]:.1f} mm, "
            f"{best_miss[1]:.2f} deg away)",
            best_miss,
        )
    q, e, iterations = min(found, key=lambda f: float(np.max(np.abs(f[0] - q_current))))
    return IKSolution(
        q, float(np.linalg.norm(e[:3])), float(np.degrees(np.linalg.norm(e[3:]))), iterations, len(found), tried
    )
