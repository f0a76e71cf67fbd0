"""A "true" robot that differs from its model the way real robots do.

Joint zero offsets, link length errors, a base placement error and a hand-eye (camera
mounting) error, each configurable and each possibly zero. Commanding the model's IK joints
then leaves the true tool a few mm and a few tenths of a degree from where the model says,
as in the paper. Nothing here knows the errors' size except the test bed: the calibration
must find them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from calib_core.frames import concat, invert, transform_from_xyz_rpy
from calib_core.robot.model import RobotModel


@dataclass(frozen=True)
class RobotErrors:
    """How the true robot differs from the model.

    ``joint_offsets_deg`` (n,): added to every commanded joint (deg or mm). ``link_errors_mm`` (n, 3):
    added to each joint's placement in its parent (the link lengths and offsets). Empty (the
    default) means zero for every joint, whatever the robot's count. ``base_xyz_mm``,
    ``base_rpy_deg``: the true base placement relative to the modelled one.
    ``hand_eye_xyz_mm``, ``hand_eye_rpy_deg``: the true camera mounting relative to the
    modelled one, in the modelled camera frame.
    """

    joint_offsets_deg: np.ndarray = field(default_factory=lambda: np.zeros(0))
    link_errors_mm: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    base_xyz_mm: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_rpy_deg: np.ndarray = field(default_factory=lambda: np.zeros(3))
    hand_eye_xyz_mm: np.ndarray = field(default_factory=lambda: np.zeros(3))
    hand_eye_rpy_deg: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @classmethod
    def none(cls) -> RobotErrors:
        return cls()

    @classmethod
    def typical(cls, seed: int = 0, *, n_joints: int = 6) -> RobotErrors:
        """Errors of a real, uncalibrated industrial arm: joint offsets 0.1-0.2 deg, link errors
        0.3-1 mm, base 0.5-1.5 mm and 0.02-0.05 deg, hand-eye 0.5-1 mm and 0.05-0.2 deg; random
        signs. Together they put the tool a few mm and a few tenths of a degree off."""
        rng = np.random.default_rng(seed)

        def signed(lo, hi, shape):
            return rng.uniform(lo, hi, shape) * rng.choice([-1.0, 1.0], shape)

        link = np.zeros((n_joints, 3))
        link[1:] = signed(0.3, 1.0, (n_joints - 1, 3))
        return cls(
            joint_offsets_deg=signed(0.1, 0.2, n_joints),
            link_errors_mm=link,
            base_xyz_mm=signed(0.5, 1.5, 3),
            base_rpy_deg=signed(0.02, 0.05, 3),
            hand_eye_xyz_mm=signed(0.5, 1.0, 3),
            hand_eye_rpy_deg=signed(0.05, 0.2, 3),
        )


def _per_joint(values, shape: tuple[int, ...], name: str) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return np.zeros(shape)
    if values.shape != shape:
        raise ValueError(f"RobotErrors.{name}: expected shape {shape} for this robot, got {values.shape}")
    return values


class TrueRobot:
    """The physical robot of the simulated test bed: the model with :class:`RobotErrors` applied."""

    def __init__(self, model: RobotModel, errors: RobotErrors):
        self.errors = errors
        self.model_robot = model
        self.robot = model.copy()
        n = model.n_joints
        self.joint_offsets = _per_joint(errors.joint_offsets_deg, (n,), "joint_offsets_deg")
        link_errors = _per_joint(errors.link_errors_mm, (n, 3), "link_errors_mm")
        for j in range(1, self.robot.model.njoints):
            placement = self.robot.model.jointPlacements[j]
            delta = link_errors[j - 1] / 1000.0
            self.robot.model.jointPlacements[j] = pin.SE3(placement.rotation, placement.translation + delta)
        self.base_true2base_model = transform_from_xyz_rpy(errors.base_xyz_mm, errors.base_rpy_deg)
        cam_error = transform_from_xyz_rpy(errors.hand_eye_xyz_mm, errors.hand_eye_rpy_deg)
        self.robot.set_frame_placement("camera", concat(cam_error, model.frame_placement("camera")))

    def true_joints(self, q_commanded_deg: ArrayLike) -> np.ndarray:
        """Where the joints really are when ``q_commanded_deg`` is commanded (and reported)."""
        return self.robot.check_joints(q_commanded_deg) + self.joint_offsets

    def fk(self, q_commanded_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """The true ``frame2base`` (4, 4) mm, in the modelled base frame, at commanded joints."""
        return concat(self.robot.fk(self.true_joints(q_commanded_deg), frame), self.base_true2base_model)

    def tool_error(self, q_commanded_deg: ArrayLike, frame: str = "tcp") -> np.ndarray:
        """``true2model`` of a frame at commanded joints: where the model is wrong (4, 4) mm."""
        return concat(self.fk(q_commanded_deg, frame), invert(self.model_robot.fk(q_commanded_deg, frame)))
