"""A robot loaded from URDF with Pinocchio: forward kinematics and Jacobians of any frame.

Every argument and result is in mm and degrees; Pinocchio works in metres and radians
inside this module only. Joint vectors are ``q_deg`` (6,), in the URDF's joint order.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from calib_core.errors import FileFormatError
from calib_core.robot.errors import RobotModelError, UnknownFrameError

RESOURCES = Path(__file__).resolve().parents[2] / "resources" / "robot"
DEFAULT_URDF = RESOURCES / "videocal_arm.urdf"


def _to_mm(placement: pin.SE3) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = placement.rotation
    T[:3, 3] = placement.translation * 1000.0
    return T


def _to_se3(T_mm: np.ndarray) -> pin.SE3:
    return pin.SE3(np.asarray(T_mm[:3, :3], dtype=float), np.asarray(T_mm[:3, 3], dtype=float) / 1000.0)


@dataclass
class RobotModel:
    """A serial robot. ``model``/``data`` are Pinocchio's; ``urdf_path`` where it came from.

    Frames of interest (names in the bundled URDF): ``base_link``, ``flange``, ``tcp``
    (tool centre point, z along the approach) and ``camera`` (OpenCV axes).
    """

    model: pin.Model
    data: pin.Data
    urdf_path: Path

    @property
    def joint_names(self) -> list[str]:
        return [self.model.names[i] for i in range(1, self.model.njoints)]

    @property
    def n_joints(self) -> int:
        return self.model.nq

    @property
    def lower_limits_deg(self) -> np.ndarray:
        return np.degrees(self.model.lowerPositionLimit)

    @property
    def upper_limits_deg(self) -> np.ndarray:
        return np.degrees(self.model.upperPositionLimit)

    @property
    def max_speed_deg_s(self) -> np.ndarray:
        return np.degrees(self.model.velocityLimit)

    @property
    def frame_names(self) -> list[str]:
        return [f.name for f in self.model.frames]

    def frame_id(self, name: str) -> int:
        """Pinocchio's id of frame ``name``; :class:`UnknownFrameError` if there is none
        (``getFrameId`` alone would return an out-of-range id)."""
        if not self.model.existFrame(name):
            raise UnknownFrameError(name, self.frame_names)
        return self.model.getFrameId(name)

    def check_joints(self, q_deg: ArrayLike) -> np.ndarray:
        """``q_deg`` as a float array (n,); :class:`RobotModelError` if its length or values are wrong."""
        q = np.asarray(q_deg, dtype=float).reshape(-1)
        if q.shape != (self.n_joints,):
            raise RobotModelError(f"expected {self.n_joints} joint values (deg), got {q.size}")
        if not np.all(np.isfinite(q)):
            raise RobotModelError(f"joint values must be finite, got {q.tolist()}")
        return q

    def within_limits(self, q_deg: ArrayLike, margin_deg: float = 0.0) -> np.ndarray:
        """Boolean (n,): which joints lie inside their limits by at least ``margin_deg``."""
        q = self.check_joints(q_deg)
        return (q >= self.lower_limits_deg + margin_deg) & (q <= self.upper_limits_deg - margin_deg)

    def fk(self, q_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """``frame2base`` (4, 4), mm, at joints ``q_deg`` (n,) deg."""
        fid = self.frame_id(frame)
        pin.framesForwardKinematics(self.model, self.data, np.radians(self.check_joints(q_deg)))
        return _to_mm(self.data.oMf[fid])

    def all_frames(self, q_deg: ArrayLike) -> dict[str, np.ndarray]:
        """``frame2base`` (4, 4) mm of every frame at ``q_deg``."""
        pin.framesForwardKinematics(self.model, self.data, np.radians(self.check_joints(q_deg)))
        return {f.name: _to_mm(self.data.oMf[i]) for i, f in enumerate(self.model.frames)}

    def jacobian(self, q_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """Frame Jacobian (6, n) in base axes at the frame's origin: rows ``v`` (mm/rad) then
        ``omega`` (rad/rad), columns per joint (a joint rate in rad/s gives mm/s and rad/s)."""
        fid = self.frame_id(frame)
        q = np.radians(self.check_joints(q_deg))
        J = pin.computeFrameJacobian(self.model, self.data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        J = np.array(J)
        J[:3] *= 1000.0
        return J

    def set_frame_placement(self, frame: str, frame2parent_mm: np.ndarray) -> None:
        """Move a fixed frame relative to its parent joint (e.g. a calibrated ``camera``)."""
        self.model.frames[self.frame_id(frame)].placement = _to_se3(frame2parent_mm)

    def frame_placement(self, frame: str) -> np.ndarray:
        """The frame's placement in its parent joint's frame (4, 4), mm."""
        return _to_mm(self.model.frames[self.frame_id(frame)].placement)

    def copy(self) -> RobotModel:
        model = self.model.copy()
        return RobotModel(model, model.createData(), self.urdf_path)


def load_robot(urdf_path: str | Path = DEFAULT_URDF) -> RobotModel:
    """Load a URDF; :class:`FileFormatError` names the file when it is missing or malformed."""
    path = Path(urdf_path)
    if not path.is_file():
        raise FileFormatError(path, "no such URDF file")
    try:
        model = pin.buildModelFromUrdf(str(path))
    except (RuntimeError, ValueError) as exc:
        raise FileFormatError(path, f"not a usable URDF: {exc}") from None
    if model.nq == 0:
        raise FileFormatError(path, "the URDF has no movable joints")
    return RobotModel(model, model.createData(), path)
