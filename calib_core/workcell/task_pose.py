"""Where a new cell's task goes: in front of the arm, at a pose the arm takes unfolded.

A task placed by the tool's reach alone put the wrist near the robot's first axis (the tool, its offset and the approach
point back at the robot): every vendor arm reached it folded (a KR 6 at A2 -143 deg, A3 +144 deg, its upper arm
leaning back over the base). Here the task is placed by the **wrist**: at a share of the arm's length (shoulder to
elbow to wrist) from the shoulder, the tool pointing forward from there; and of the joints that reach it, the ones
the arm takes **unfolded** are chosen: the elbow above the line from shoulder to wrist, the upper arm not leaning
back, the elbow opened past :data:`FOLDED_BELOW_DEG`.

The geometry is read from the robot's joints (their origins), not a table per model: for a six-axis arm the
shoulder is axis 2, the elbow axis 3 and the wrist axis 5 (where axes 4, 5 and 6 meet on a spherical wrist); for a
seven-axis arm axes 2, 4 and 6. Any other chain keeps the first reachable pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.frames import make_transform
from calib_core.robot import UnreachableTargetError, solve_ik
from calib_core.robot.model import RobotModel

FOLDED_BELOW_DEG = 60.0
"""An elbow closed tighter than this (the angle at the elbow between shoulder and wrist) is folded."""
LEAN_BACK_SHARE = 0.15
"""The upper arm leans back when its forward run is below minus this share of its length."""
WRIST_SHARES = (0.7, 0.6, 0.8, 0.5, 0.9)
"""Shoulder-to-wrist distance at the approach, as shares of the arm's length, in the order tried."""
RISES = (0.0, 0.25, -0.25, 0.5)
"""The wrist's height above the shoulder, as shares of the arm's length, in the order tried."""
SEEDS = 10
"""Joint seeds per candidate pose: each converges to one of the arm's ways of standing there."""


@dataclass(frozen=True)
class ArmJoints:
    """Indices (in the robot's joint order) of the shoulder, elbow and wrist axes."""

    shoulder: int
    elbow: int
    wrist: int

    @classmethod
    def of(cls, robot: RobotModel) -> ArmJoints | None:
        return {6: cls(1, 2, 4), 7: cls(1, 3, 5)}.get(robot.n_joints)

    def points(self, robot: RobotModel, q_deg) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The origins (3,), mm in the base frame, of the first axis, shoulder, elbow and wrist at ``q_deg``."""
        names = robot.model.names
        return tuple(robot.fk(q_deg, names[k + 1])[:3, 3] for k in (0, self.shoulder, self.elbow, self.wrist))


@dataclass(frozen=True)
class Posture:
    """How the arm stands: ``elbow_deg`` the angle at the elbow between shoulder and wrist, ``elbow_up`` the elbow
    above the shoulder-wrist line, ``lean_back`` the upper arm's run away from the wrist, ``wrist_in_front`` the wrist
    on the task's side of the first axis."""

    elbow_deg: float
    elbow_up: bool
    lean_back: bool
    wrist_in_front: bool

    @property
    def unfolded(self) -> bool:
        return self.elbow_up and not self.lean_back and self.wrist_in_front and self.elbow_deg >= FOLDED_BELOW_DEG


def posture(robot: RobotModel, joints: ArmJoints, q_deg, forward: np.ndarray) -> Posture:
    """The posture at ``q_deg`` (deg) for a task toward ``forward`` (3,), a horizontal unit vector of the base frame."""
    axis1, shoulder, elbow, wrist = joints.points(robot, q_deg)
    upper, fore = elbow - shoulder, wrist - elbow
    cos = float(np.dot(-upper, fore) / (np.linalg.norm(upper) * np.linalg.norm(fore) + 1e-12))
    reach = wrist - shoulder
    # in the vertical plane of the task: (forward, up) coordinates; the line's upward normal
    d = np.array([reach @ forward, reach[2]])
    e = np.array([upper @ forward, upper[2]])
    normal = np.array([-d[1], d[0]])
    return Posture(
        elbow_deg=float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))),
        elbow_up=bool(e @ normal > 0.0),
        lean_back=bool(upper @ forward < -LEAN_BACK_SHARE * np.linalg.norm(upper)),
        wrist_in_front=bool((wrist - axis1) @ forward > 0.0),
    )


def _wrist_twin(robot: RobotModel, joints: ArmJoints, q: np.ndarray) -> np.ndarray | None:
    """The same tool pose with the wrist turned the other way round (a spherical wrist's axes ``w-1, w, w+1``:
    ``+180, negated, +180``, each wrapped toward zero), if within the limits and it does put the tool there."""
    w = joints.wrist
    if w + 1 >= robot.n_joints:
        return None
    twin = q.copy()
    twin[w - 1] = (q[w - 1] + 360.0) % 360.0 - 180.0
    twin[w] = -q[w]
    twin[w + 1] = (q[w + 1] + 360.0) % 360.0 - 180.0
    if np.any(twin < robot.lower_limits_deg) or np.any(twin > robot.upper_limits_deg):
        return None
    if np.linalg.norm(robot.fk(twin, "tcp")[:3, 3] - robot.fk(q, "tcp")[:3, 3]) > 0.01:
        return None  # not a spherical wrist
    return twin


def _ways_to_stand(
    robot: RobotModel, joints: ArmJoints, target2base: np.ndarray, seeds: list[np.ndarray]
) -> list[np.ndarray]:
    found = []
    for seed in seeds:
        try:
            q = solve_ik(robot, target2base, seed, extra_seeds=0).q_deg
        except UnreachableTargetError:
            continue
        for way in (q, _wrist_twin(robot, joints, q)):
            if way is not None and not any(np.allclose(way, other, atol=1.0) for other in found):
                found.append(way)
    return found


def find_task(
    robot: RobotModel, tool2base_rotation: np.ndarray, home: np.ndarray, approach_mm: float, min_z_mm: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """A grasp (tcp2base, (4, 4), mm; the tool along base +x with ``tool2base_rotation``) that the arm reaches
    unfolded from ``approach_mm`` back along the tool, and the joints (deg) at that approach; ``None`` when the arm's
    joints are not read here (see the module) or no candidate is reached unfolded."""
    joints = ArmJoints.of(robot)
    if joints is None:
        return None
    forward = np.array([1.0, 0.0, 0.0])
    axis1, shoulder, elbow, wrist = joints.points(robot, home)
    arm = float(np.linalg.norm(elbow - shoulder) + np.linalg.norm(wrist - elbow))
    wrist2tcp = float(np.linalg.norm(robot.fk(home, "tcp")[:3, 3] - wrist))  # a spherical wrist's centre: any pose
    rng = np.random.default_rng(0)
    lo, hi = np.maximum(robot.lower_limits_deg, -170.0), np.minimum(robot.upper_limits_deg, 170.0)
    seeds = [home] + [rng.uniform(lo, hi) for _ in range(SEEDS - 1)]
    for share in WRIST_SHARES:
        for rise in RISES:
            run = (share * arm) ** 2 - (rise * arm) ** 2
            if run <= 0.0:
                continue
            approach_x = shoulder[0] + np.sqrt(run) + wrist2tcp
            z = shoulder[2] + rise * arm
            if z < min_z_mm:
                continue
            approach = make_transform(tool2base_rotation, [approach_x, 0.0, z])
            tcp = make_transform(tool2base_rotation, [approach_x + approach_mm, 0.0, z])
            standing = [
                q for q in _ways_to_stand(robot, joints, approach, seeds) if posture(robot, joints, q, forward).unfolded
            ]
            for q in sorted(standing, key=lambda q: float(np.max(np.abs(q - home)))):
                try:
                    q_grasp = solve_ik(robot, tcp, q, extra_seeds=0).q_deg
                except UnreachableTargetError:
                    continue
                if posture(robot, joints, q_grasp, forward).unfolded:
                    return tcp, q
    return None
