"""Between the robot model's joints and the controller's axes.

A controller numbers its axes its own way and may zero them elsewhere than the URDF (the
workcell's ``robot.controller``: :class:`~calib_core.robot.spec.ControllerMap`). The link
carries controller values; everything above the link uses the model's (URDF order, URDF zero).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from calib_core.robot.spec import ControllerMap


@dataclass(frozen=True)
class JointMap:
    """``order[i]``: the model joint index of controller axis i; controller value = model value
    + ``offsets[i]`` (deg or mm)."""

    order: np.ndarray
    offsets: np.ndarray

    @classmethod
    def identity(cls, n_joints: int) -> JointMap:
        return cls(np.arange(n_joints), np.zeros(n_joints))

    @classmethod
    def for_robot(cls, joint_names: list[str], controller: ControllerMap | None) -> JointMap:
        """The map of a robot whose driven joints are ``joint_names`` (URDF order)."""
        if controller is None:
            return cls.identity(len(joint_names))
        return cls(
            np.array([joint_names.index(j) for j in controller.joints]),
            np.asarray(controller.zero_offsets, dtype=float),
        )

    @property
    def n_joints(self) -> int:
        return len(self.order)

    def to_controller(self, q_model: ArrayLike) -> np.ndarray:
        """Controller axis values (n,) of model joints (n,)."""
        return np.asarray(q_model, dtype=float)[self.order] + self.offsets

    def to_model(self, q_controller: ArrayLike) -> np.ndarray:
        """Model joints (n,) of controller axis values (n,)."""
        q = np.empty(self.n_joints)
        q[self.order] = np.asarray(q_controller, dtype=float) - self.offsets
        return q


@dataclass(frozen=True)
class ControllerJointModel:
    """A robot's limits and speeds as its controller sees them (axis order and zero), for the
    simulator: what :class:`~calib_core.link.joint_motion.JointModel` asks."""

    lower_limits_deg: np.ndarray
    upper_limits_deg: np.ndarray
    max_speed_deg_s: np.ndarray

    @classmethod
    def of(cls, robot, joint_map: JointMap) -> ControllerJointModel:
        lo = robot.lower_limits_deg[joint_map.order] + joint_map.offsets
        hi = robot.upper_limits_deg[joint_map.order] + joint_map.offsets
        speed = robot.max_speed_deg_s[joint_map.order]
        return cls(lo, hi, np.where(speed > 0, speed, 100.0))
