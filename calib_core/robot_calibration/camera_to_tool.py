"""Camera to tool: where the TCP is relative to the camera, from the paper's fixtures and compliance.

A camera sees camera poses, so board and cell views leave the tool's offset from the camera to the
model (and, worse, a camera-only calibration may put the last joint's along-axis translation and its
rotation into the mounting, which moves the TCP by as much). A fixture pin of the cell fixes it: the
operator jogs the open gripper over a surveyed pin and closes it with the controller in compliance,
so the fingers centre the TCP on the pin whatever the robot's errors. The joints then reported, with
the calibrated robot's camera at those joints, give the TCP in the camera frame::

    tcp2cam = (cam2base at the reported joints)^-1 . tcp2base (the pin's surveyed grasp)

When the camera also sees the fixture it holds, the grasp is *seen*
(:mod:`calib_core.robot_calibration.grasp_view`): its view gives ``tcp2cam`` directly, and neither the
fixture's survey nor the calibrated camera enters (0.01 mm against the survey's 0.05 mm per axis).

Each grasp is one measurement; several (other pins, or the same pin approached turned about its axis
when the gripper allows) are averaged and their spread reported. :func:`with_tool` puts the result into
the robot's TCP frame, on the camera's joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.calibration.look_fusion import tcp_covariance_from_camera
from calib_core.errors import VideocalError
from calib_core.frames import concat, invert, make_transform, pose_difference
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.grasp_view import SeenGrasp


class CameraToToolError(VideocalError, ValueError):
    """Grasps that cannot give the tool's offset (none, or frames on different joints)."""


@dataclass(frozen=True)
class Grasp:
    """The gripper closed on a surveyed fixture: the reported ``joints_deg`` and the grasp ``tcp2base``
    (4, 4) mm the fixture's survey gives (a task location's ``tcp2base``); ``seen``: the camera's view
    of the held fixture at those joints, when it was measured."""

    name: str
    joints_deg: np.ndarray
    tcp2base: np.ndarray
    seen: SeenGrasp | None = None


@dataclass(frozen=True)
class CameraToTool:
    """``tcp2cam`` (4, 4) mm, the mean of ``per_grasp``; ``spread_mm``/``spread_deg`` the largest
    distance of a grasp's estimate from the mean (0 for one grasp: no check of its own);
    ``covariance`` (6, 6: the TCP's position mm and rotation deg, camera axes) when the grasps' own
    uncertainty was given, else ``None``."""

    tcp2cam: np.ndarray
    per_grasp: dict[str, np.ndarray]
    spread_mm: float
    spread_deg: float
    covariance: np.ndarray | None = None
    seen_grasps: int = 0
    """How many grasps the camera saw (:mod:`calib_core.robot_calibration.grasp_view`): they alone make the tool."""

    def covariance_in_base(self, cam2base: np.ndarray) -> np.ndarray | None:
        """The tool's covariance (6, 6: mm, deg) in the base frame's axes with the camera at ``cam2base``."""
        if self.covariance is None:
            return None
        R = np.kron(np.eye(2), cam2base[:3, :3])
        return R @ self.covariance @ R.T


def camera_to_tool(
    robot: RobotModel,
    grasps: list[Grasp],
    camera_frame: str = "camera",
    *,
    placement_sigma_mm: float | None = None,
    camera_covariance=None,
) -> CameraToTool:
    """``tcp2cam`` from ``grasps``: a seen grasp's own, the others' with ``robot`` (calibrated)
    placing the camera.

    A seen grasp carries its covariance. For the others, with ``placement_sigma_mm`` (the survey's 1-sigma per axis of
    each grasped fixture) the tool gets a
    covariance: the fixture's survey error goes whole into its grasp's estimate (the gripper centres the
    TCP on the fixture as it truly stands, the estimate takes it where the workcell file places it), and
    ``camera_covariance(joints_deg)`` (6, 6: mm, mrad, base axes; the calibrated model's camera) adds the
    camera's at each grasp. Grasps of different fixtures are independent: their mean has 1/n of it.
    When some grasps are seen, only they make the tool (five times better than a survey's, an equal
    weight for the others would only add their error); it then has a covariance, as it has with
    ``placement_sigma_mm``."""
    if not grasps:
        raise CameraToToolError("no grasp: close the gripper on a surveyed fixture pin at least once")
    grasps = [g for g in grasps if g.seen is not None] or list(grasps)
    cams = {g.name: robot.fk(g.joints_deg, camera_frame) for g in grasps}
    per = {g.name: g.seen.tcp2cam if g.seen is not None else concat(g.tcp2base, invert(cams[g.name])) for g in grasps}
    Ts = list(per.values())
    mean = make_transform(
        Rotation.from_matrix([T[:3, :3] for T in Ts]).mean().as_matrix(), np.mean([T[:3, 3] for T in Ts], axis=0)
    )
    spreads = [pose_difference(T, mean) for T in Ts]
    covariance = None
    if placement_sigma_mm is not None or all(g.seen is not None for g in grasps):
        total = np.zeros((6, 6))
        for g in grasps:
            if g.seen is not None:
                total += g.seen.covariance
                continue
            in_base = np.diag([placement_sigma_mm**2] * 3 + [0.0] * 3)
            if camera_covariance is not None:
                in_base = in_base + tcp_covariance_from_camera(
                    camera_covariance(g.joints_deg), cams[g.name], per[g.name]
                )
            R = np.kron(np.eye(2), cams[g.name][:3, :3].T)
            total += R @ in_base @ R.T
        covariance = total / len(grasps) ** 2
    return CameraToTool(
        mean,
        per,
        max(float(np.linalg.norm(d)) for d, _ in spreads),
        max(float(np.linalg.norm(r)) for _, r in spreads),
        covariance,
        sum(g.seen is not None for g in grasps),
    )


def with_tool(
    robot: RobotModel, tcp2cam: np.ndarray, tcp_frame: str = "tcp", camera_frame: str = "camera"
) -> RobotModel:
    """A copy of ``robot`` whose TCP is ``tcp2cam`` from its camera (both frames on one joint)."""
    tcp_id, cam_id = robot.frame_id(tcp_frame), robot.frame_id(camera_frame)
    if robot.model.frames[tcp_id].parentJoint != robot.model.frames[cam_id].parentJoint:
        raise CameraToToolError(
            f"the {tcp_frame} and {camera_frame} frames move with different joints: the camera must ride on the tool's "
            "joint"
        )
    out = robot.copy()
    out.set_frame_placement(tcp_frame, concat(tcp2cam, robot.frame_placement(camera_frame)))
    return out
