"""Camera to tool: where the TCP is relative to the camera, from the paper's fixtures and compliance.

A camera sees camera poses, so board and cell views leave the tool's offset from the camera to the
model (and, worse, a camera-only calibration may put the last joint's along-axis translation and its
rotation into the mounting, which moves the TCP by as much). A fixture pin of the cell fixes it: the
operator jogs the open gripper over a surveyed pin and closes it with the controller in compliance,
so the fingers centre the TCP on the pin whatever the robot's errors. The joints then reported, with
the calibrated robot's camera at those joints, give the TCP in the camera frame::

    tcp2cam = (cam2base at the reported joints)^-1 . tcp2base (the pin's surveyed grasp)

Each grasp is one measurement; several (other pins, or the same pin approached turned about its axis
when the gripper allows) are averaged and their spread reported. :func:`with_tool` puts the result into
the robot's TCP frame, on the camera's joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.errors import VideocalError
from calib_core.frames import invert, make_transform, pose_difference
from calib_core.robot.model import RobotModel


class CameraToToolError(VideocalError, ValueError):
    """Grasps that cannot give the tool's offset (none, or frames on different joints)."""


@dataclass(frozen=True)
class Grasp:
    """The gripper closed on a surveyed fixture: the reported ``joints_deg`` and the grasp ``tcp2base``
    (4, 4) mm the fixture's survey gives (a task location's ``tcp2base``)."""

    name: str
    joints_deg: np.ndarray
    tcp2base: np.ndarray


@dataclass(frozen=True)
class CameraToTool:
    """``tcp2cam`` (4, 4) mm, the mean of ``per_grasp``; ``spread_mm``/``spread_deg`` the largest
    distance of a grasp's estimate from the mean (0 for one grasp: no check of its own)."""

    tcp2cam: np.ndarray
    per_grasp: dict[str, np.ndarray]
    spread_mm: float
    spread_deg: float


def camera_to_tool(robot: RobotModel, grasps: list[Grasp], camera_frame: str = "camera") -> CameraToTool:
    """``tcp2cam`` from ``grasps`` with ``robot`` (calibrated) placing the camera."""
    if not grasps:
        raise CameraToToolError("no grasp: close the gripper on a surveyed fixture pin at least once")
    per = {g.name: invert(robot.fk(g.joints_deg, camera_frame)) @ np.asarray(g.tcp2base, dtype=float) for g in grasps}
    Ts = list(per.values())
    mean = make_transform(Rotation.from_matrix([T[:3, :3] for T in Ts]).mean().as_matrix(), np.mean([T[:3, 3] for T in Ts], axis=0))
    spreads = [pose_difference(T, mean) for T in Ts]
    return CameraToTool(mean, per, max(float(np.linalg.norm(d)) for d, _ in spreads), max(float(np.linalg.norm(r)) for _, r in spreads))


def with_tool(robot: RobotModel, tcp2cam: np.ndarray, tcp_frame: str = "tcp", camera_frame: str = "camera") -> RobotModel:
    """A copy of ``robot`` whose TCP is ``tcp2cam`` from its camera (both frames on one joint)."""
    tcp_id, cam_id = robot.frame_id(tcp_frame), robot.frame_id(camera_frame)
    if robot.model.frames[tcp_id].parentJoint != robot.model.frames[cam_id].parentJoint:
        raise CameraToToolError(f"the {tcp_frame} and {camera_frame} frames move with different joints: the camera must ride on the tool's joint")
    out = robot.copy()
    out.set_frame_placement(tcp_frame, robot.frame_placement(camera_frame) @ np.asarray(tcp2cam, dtype=float))
    return out
