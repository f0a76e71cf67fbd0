"""The robot model: URDF loaded with Pinocchio; forward kinematics, Jacobians and inverse
kinematics of any frame, in mm and degrees at the boundary (Pinocchio's metres inside)."""

from calib_core.robot.errors import RobotModelError, UnknownFrameError, UnreachableTargetError
from calib_core.robot.ik import IKSolution, solve_ik
from calib_core.robot.model import RobotModel, load_robot

__all__ = [
    "RobotModel",
    "load_robot",
    "solve_ik",
    "IKSolution",
    "RobotModelError",
    "UnknownFrameError",
    "UnreachableTargetError",
]
