"""The geometric error model of a robot seen by its camera, and a working copy of the robot that
takes a parameter vector.

Every driven joint's placement in its parent (Pinocchio's ``jointPlacements``, the URDF joint origin
with any fixed joints before it folded in) gets a small 6-DoF correction applied before it, in the
parent's frame: ``x y z`` (mm) and a rotation vector ``rx ry rz`` (mrad). The camera's placement on
its joint gets one too. This spans what real robots get wrong: a joint's zero offset is a rotation
about its axis, a link length a translation, the base's placement the first joint's correction (the
cell's surveyed placements are in the base frame, so the base error is the first joint's), the
camera mounting the camera's. Many of these directions are redundant (a translation along a revolute
axis and the next link's); :mod:`calib_core.robot_calibration.observability` finds which combinations
the views determine. Intrinsics corrections (fu fv cx cy px, k1 k2 p1 p2 in thousandths) are optional.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.robot.model import RobotModel, _to_mm, _to_se3

AXES = ("x_mm", "y_mm", "z_mm", "rx_mrad", "ry_mrad", "rz_mrad")
INTRINSICS = ("fu_px", "fv_px", "cx_px", "cy_px", "k1_e3", "k2_e3", "p1_e3", "p2_e3")


def delta_transform(v: np.ndarray) -> np.ndarray:
    """A small correction (4, 4) mm from ``v`` = (x, y, z mm, rx, ry, rz mrad)."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.asarray(v[3:6], dtype=float) / 1000.0).as_matrix()
    T[:3, 3] = v[:3]
    return T


def corrected_intrinsics(nominal: Intrinsics, d: np.ndarray) -> Intrinsics:
    """``nominal`` with the corrections ``d`` (8,) in the units of :data:`INTRINSICS` applied."""
    dist = np.asarray(nominal.distortion, dtype=float).copy()
    dist[:4] += (
        np.asarray(d[4:8], dtype=float) / 1000.0
    )  # the first four of any model: k1 k2 p1 p2, or a fisheye's k1..k4
    return replace(
        nominal,
        fu=nominal.fu + d[0],
        fv=nominal.fv + d[1],
        cx=nominal.cx + d[2],
        cy=nominal.cy + d[3],
        distortion=tuple(dist),
    )


def delta_of(T: np.ndarray) -> np.ndarray:
    """The inverse of :func:`delta_transform`: (x, y, z mm, rx, ry, rz mrad) of a (4, 4) mm."""
    return np.r_[T[:3, 3], 1000.0 * Rotation.from_matrix(T[:3, :3]).as_rotvec()]


@dataclass(frozen=True)
class ParameterLayout:
    """Names and units of the parameter vector: one block of :data:`AXES` per driven joint (by its
    URDF name), one for ``camera``, then :data:`INTRINSICS` when ``with_intrinsics``."""

    joint_names: tuple[str, ...]
    with_intrinsics: bool = False

    @property
    def names(self) -> list[str]:
        out = [f"{j}.{a}" for j in self.joint_names for a in AXES] + [f"camera.{a}" for a in AXES]
        return out + [f"intrinsics.{a}" for a in INTRINSICS] if self.with_intrinsics else out

    @property
    def size(self) -> int:
        return 6 * (len(self.joint_names) + 1) + (len(INTRINSICS) if self.with_intrinsics else 0)

    @property
    def scale(self) -> np.ndarray:
        """A typical size of each parameter (1 mm, 1 mrad, 1 px, 0.001): columns of an identification
        Jacobian times this are comparable."""
        return np.ones(self.size)

    def joint_block(self, j: int) -> slice:
        return slice(6 * j, 6 * j + 6)

    @property
    def camera_block(self) -> slice:
        n = len(self.joint_names)
        return slice(6 * n, 6 * n + 6)

    @property
    def intrinsics_block(self) -> slice:
        n = 6 * (len(self.joint_names) + 1)
        return slice(n, n + len(INTRINSICS))


class CorrectedRobot:
    """A working copy of ``robot`` whose joint and camera placements follow a parameter vector
    (:meth:`set`); the nominal placements are kept, so any vector can be set at any time."""

    def __init__(self, robot: RobotModel, camera_frame: str = "camera", with_intrinsics: bool = False):
        self.nominal = robot
        self.robot = robot.copy()
        self.camera_frame = camera_frame
        self.layout = ParameterLayout(tuple(robot.joint_names), with_intrinsics)
        self._placements = [_to_mm(robot.model.jointPlacements[j]) for j in range(1, robot.model.njoints)]
        self._camera = robot.frame_placement(camera_frame)
        self._camera_id = self.robot.frame_id(camera_frame)
        self.parameters = np.zeros(self.layout.size)

    def set(self, p: np.ndarray) -> None:
        p = np.asarray(p, dtype=float)
        model = self.robot.model
        for j, nominal in enumerate(self._placements):
            model.jointPlacements[j + 1] = _to_se3(delta_transform(p[self.layout.joint_block(j)]) @ nominal)
        model.frames[self._camera_id].placement = _to_se3(delta_transform(p[self.layout.camera_block]) @ self._camera)
        self.parameters = p.copy()

    def cam2base(self, q_deg) -> np.ndarray:
        return self.robot.fk(q_deg, self.camera_frame)

    def intrinsics(self, nominal: Intrinsics) -> Intrinsics:
        """``nominal`` with the intrinsics corrections applied (itself without them)."""
        if not self.layout.with_intrinsics:
            return nominal
        return corrected_intrinsics(nominal, self.parameters[self.layout.intrinsics_block])

    def calibrated_model(self) -> RobotModel:
        """A copy of the robot with the current corrections: the calibrated robot."""
        return self.robot.copy()


def joint_placement(robot: RobotModel, j: int) -> np.ndarray:
    """The placement (4, 4) mm of driven joint ``j`` (0-based) in its parent joint's frame."""
    return _to_mm(robot.model.jointPlacements[j + 1])
