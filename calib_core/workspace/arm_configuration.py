"""The arm's configuration at a target, as the controllers declare it beside a Cartesian pose.

A pose alone leaves a six-axis arm up to eight ways to stand (and more turns of its axes); each controller names
the one it should take in its own terms. Here they are derived from the joints the robot will take at the target:
IK on the cell's robot from the joints the look was made at (the corrected target is millimetres from there, so the
same branch), in the controller's axis values (the workcell's joint map: order and zero offsets).

The geometry is the robot's own, not a table per model: the **wrist centre** (where axes 4, 5 and 6 meet), its side of
**axis 1** (the x of the wrist centre in the axis-1 frame: the frame of the robot's base carried round by axis 1;
positive is in front, KUKA's basic area) and its side of the **lower arm** (the line through axes 2 and 3, in the arm's
plane; the side the vendor's reference pose has is the normal one).

- ABB ``confdata`` ``[cf1, cf4, cf6, cfx]`` (RAPID reference manual, *confdata*): the quadrant of axes 1, 4 and 6
  (``floor(angle / 90 deg)``: 0 for 0..90, -1 for -90..0); ``cfx`` 0..7 = 4 x (wrist centre behind axis 1) + 2 x
  (behind the lower arm) + (axis 5 negative); the lower arm's front is the side at axis 3 = 0.
- KUKA ``S`` and ``T`` (KSS expert programming manual): ``S`` bit 0 = overhead area (the wrist centre's x in the A1
  frame negative), bit 1 = A3 at or past the angle where the wrist centre crosses the line of A2 and A3 (the side of
  the normal pose A2 = -90, A3 = +90), bit 2 = A5 negative; ``T`` bit n = axis n+1 negative.
- Universal Robots: the joints themselves (``movej`` takes them, in radians).

Near a boundary (a quadrant edge, the wrist or elbow singularity) the corrected target may fall on either side:
:attr:`ArmConfiguration.near` names it, for the listing's remark.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from calib_core.errors import VideocalError

NEAR_DEG = 1.0
"""An axis within this of a configuration boundary is named: the corrected target may be on the other side."""
NEAR_MM = 2.0
"""The wrist centre within this of axis 1 or of the lower arm's line is named likewise."""


class NotASixAxisArmError(VideocalError):
    """The robot has not six revolute axes in a row with axes 4, 5 and 6 meeting (a spherical wrist)."""


@dataclass(frozen=True)
class ArmConfiguration:
    """``axes_deg`` (n,): the controller's axis values (deg) in its axis order; ``wrist_x_mm``: the wrist centre's x in
    the
    axis-1 frame (> 0 in front of axis 1); ``elbow_mm``: the wrist centre's signed distance from the lower arm's line
    (> 0 on the side of the vendor's reference pose); ``near``: boundaries within :data:`NEAR_DEG` or
    :data:`NEAR_MM`."""

    axes_deg: np.ndarray
    wrist_x_mm: float
    elbow_mm: float
    near: tuple[str, ...]

    @classmethod
    def of_axes(cls, axes_deg) -> ArmConfiguration:
        """The axes alone, for a controller that names the configuration by its joints (a UR's ``qnear``): no wrist
        centre is measured (NaN)."""
        return cls(np.asarray(axes_deg, dtype=float), float("nan"), float("nan"), ())


def _quadrant(angle_deg: float) -> int:
    return math.floor(angle_deg / 90.0)


def abb_confdata(c: ArmConfiguration) -> tuple[int, int, int, int]:
    """``[cf1, cf4, cf6, cfx]`` of RAPID's ``confdata`` (serial six-axis robots)."""
    a = c.axes_deg
    cfx = 4 * int(c.wrist_x_mm < 0) + 2 * int(c.elbow_mm < 0) + int(a[4] < 0)
    return _quadrant(a[0]), _quadrant(a[3]), _quadrant(a[5]), int(cfx)


def kuka_status_turn(c: ArmConfiguration) -> tuple[int, int]:
    """KRL's ``S`` (Status) and ``T`` (Turn) of an ``E6POS``."""
    a = c.axes_deg
    status = int(c.wrist_x_mm < 0) + 2 * int(c.elbow_mm >= 0) + 4 * int(a[4] < 0)
    turn = sum(1 << k for k in range(min(6, len(a))) if a[k] < 0)
    return status, int(turn)


@dataclass(frozen=True)
class _Axis:
    point: np.ndarray  # (3,) mm, a point of the axis in the robot's world
    direction: np.ndarray  # (3,) unit


def _axes(robot, q_model_deg) -> tuple[list[_Axis], np.ndarray]:
    """The first six joint axes at ``q_model_deg`` in the robot's world (mm), and axis 1's frame's rotation (3, 3)."""
    model = robot.model
    if model.njoints - 1 < 6:
        raise NotASixAxisArmError(
            f"the robot has {model.njoints - 1} joints; a controller's arm configuration is for six-axis arms"
        )
    data = model.createData()
    pin.computeJointJacobians(model, data, robot.configuration(q_model_deg))
    axes = []
    for j in range(1, 7):
        J = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        omega = J[3:, model.idx_vs[j]] if model.nvs[j] == 1 else np.zeros(3)
        if np.linalg.norm(omega) < 0.5:  # a prismatic joint moves, it does not turn
            raise NotASixAxisArmError(
                f"joint {model.names[j]!r} is not a revolute axis: a controller's arm configuration is for six "
                "revolute axes"
            )
        axes.append(_Axis(data.oMi[j].translation * 1000.0, omega / np.linalg.norm(omega)))
    return axes, data.oMi[1].rotation.copy()


def _closest_points(a: _Axis, b: _Axis) -> tuple[np.ndarray, np.ndarray]:
    w = a.point - b.point
    d = float(a.direction @ b.direction)
    denom = 1.0 - d * d
    if denom < 1e-9:  # parallel axes: no wrist centre
        return a.point, b.point + np.inf
    s = (d * (b.direction @ w) - (a.direction @ w)) / denom
    t = ((b.direction @ w) - d * (a.direction @ w)) / denom
    return a.point + s * a.direction, b.point + t * b.direction


def _wrist_centre(axes: list[_Axis]) -> np.ndarray:
    """Where axes 4, 5 and 6 meet (a spherical wrist); :class:`NotASixAxisArmError` when they do not."""
    p4, p5 = _closest_points(axes[3], axes[4])
    gap = float(np.linalg.norm(p4 - p5))
    centre = (p4 + p5) / 2
    off6 = centre - axes[5].point
    off6 = float(np.linalg.norm(off6 - (off6 @ axes[5].direction) * axes[5].direction)) if gap <= 1.0 else gap
    if not (gap <= 1.0 and off6 <= 1.0):
        raise NotASixAxisArmError(
            f"axes 4, 5 and 6 do not meet (they pass {max(gap, off6):.1f} mm apart): no wrist centre; "
            "an offset wrist names its configuration by its joints"
        )
    return centre


def _elbow_side(axes: list[_Axis], centre: np.ndarray) -> float:
    """The wrist centre's signed distance (mm) from the line through axes 2 and 3, in the plane normal to axis 2."""
    a2, a3 = axes[1], axes[2]
    along = a3.point - a2.point
    along = along - (along @ a2.direction) * a2.direction
    along /= np.linalg.norm(along)
    return float(np.cross(along, centre - a3.point) @ a2.direction)


def arm_configuration(robot, joint_map, q_model_deg, reference_axes_deg) -> ArmConfiguration:
    """The configuration of ``robot`` (a :class:`~calib_core.robot.model.RobotModel`) at ``q_model_deg`` (model joints),
    ``joint_map`` (:class:`~calib_core.connectors.joint_map.JointMap`) giving the controller's axis values.
    ``reference_axes_deg`` (6,) controller axes: the vendor's pose whose elbow side is the normal one (ABB: all zero;
    KUKA: A2 = -90, A3 = +90; only axes 2 and 3 matter). :class:`NotASixAxisArmError` for a robot that has none."""
    q = np.asarray(q_model_deg, dtype=float)
    axes_deg = np.asarray(joint_map.to_controller(q), dtype=float)
    axes, turn1 = _axes(robot, q)
    centre = _wrist_centre(axes)
    # The axis-1 frame: the robot's base frame carried round by axis 1 from its zero.
    _, turn1_zero = _axes(robot, joint_map.to_model(np.r_[0.0, axes_deg[1:]]))
    x_axis = turn1 @ turn1_zero.T @ np.array([1.0, 0.0, 0.0])
    x_axis -= (x_axis @ axes[0].direction) * axes[0].direction
    wrist_x = float((centre - axes[0].point) @ (x_axis / np.linalg.norm(x_axis)))
    ref_axes, _ = _axes(
        robot, joint_map.to_model(np.r_[axes_deg[:1], np.asarray(reference_axes_deg, float)[1:3], axes_deg[3:]])
    )
    ref_side = _elbow_side(ref_axes, _wrist_centre(ref_axes))
    elbow = _elbow_side(axes, centre) * (1.0 if ref_side >= 0 else -1.0)
    near = []
    for k, name in ((0, "axis 1"), (3, "axis 4"), (5, "axis 6")):
        edge = abs(axes_deg[k] - 90.0 * round(axes_deg[k] / 90.0))
        if edge < NEAR_DEG:
            near.append(f"{name} at {axes_deg[k]:.2f} deg, {edge:.2f} deg from a quadrant's edge")
    if abs(axes_deg[4]) < NEAR_DEG:
        near.append(f"axis 5 at {axes_deg[4]:.2f} deg: the wrist singularity")
    if abs(wrist_x) < NEAR_MM:
        near.append(f"the wrist centre {wrist_x:.1f} mm from axis 1")
    if abs(elbow) < NEAR_MM:
        near.append(f"the wrist centre {elbow:.1f} mm from the lower arm's line: the elbow singularity")
    return ArmConfiguration(axes_deg, wrist_x, elbow, tuple(near))
