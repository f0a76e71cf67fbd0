"""A grasp seen: the camera's view of the fixture the gripper holds gives the TCP in the camera frame.

With the gripper closed on a fixture's pin (compliance centres the TCP on it) and the camera looking
at that fixture, the edge fit of Find points gives the component's pose in the camera frame, and the
task's grasp is fixed on the component by its drawing::

    tcp2cam = obj2cam (seen) . tcp2obj (the workcell file: the task on its component)

Neither the component's survey in the cell nor the robot's calibration enters: the grasp through the
calibrated robot (:func:`~calib_core.robot_calibration.camera_to_tool.camera_to_tool` without a view)
takes the whole survey error of the fixture (0.05 mm per axis) and the calibrated camera's at the
grasp; the edges at a task location see the component to about 0.01 mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.calibration.end_effector import shared_shift_covariance
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import VideocalError
from calib_core.frames import concat, invert
from calib_core.render.model_view import ModelView
from calib_core.robot.model import RobotModel
from calib_core.robot.visuals import RobotVisuals
from calib_core.look.edge_solution import edge_solution
from calib_core.look.find_points import find_points

CENTRING_SIGMA_MM = 0.01
"""How well the closed fingers centre the TCP on the pin, 1-sigma per axis (taken from the model: a
centring gripper on a ground pin repeats to a few hundredths of a millimetre)."""


class GraspNotSeenError(VideocalError, ValueError):
    """The camera did not see the grasped fixture well enough to measure the tool from it."""


@dataclass(frozen=True)
class SeenGrasp:
    """``tcp2cam`` (4, 4) mm from the view; ``covariance`` (6, 6: the TCP's position mm and rotation
    deg, camera axes): the edge fit's, the image points' shared error and the fingers' centring."""

    tcp2cam: np.ndarray
    covariance: np.ndarray
    component: str
    edge_samples: int


def tcp_covariance_in_camera(obj2cam: np.ndarray, tcp2obj: np.ndarray, pose_covariance: np.ndarray) -> np.ndarray:
    """The covariance (6, 6: mm, deg, camera axes) of ``tcp2cam = obj2cam . tcp2obj`` from that of
    ``obj2cam`` (6, 6: the solver's dt mm and phi rad, a turn ``exp(phi) R`` and a shift ``t + dt``):
    the TCP moves by ``dt + phi x (R p)`` (``p`` its place on the object) and turns by ``phi``."""
    r = obj2cam[:3, :3] @ tcp2obj[:3, 3]
    lever = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    J = np.zeros((6, 6))
    J[:3, :3] = np.eye(3)
    J[:3, 3:] = -lever
    J[3:, 3:] = np.eye(3) * np.degrees(1.0)
    return J @ np.asarray(pose_covariance, dtype=float) @ J.T


def see_grasp(
    image: np.ndarray,
    intrinsics: Intrinsics,
    robot: RobotModel,
    workcell,
    task,
    joints_deg,
    camera_frame: str = "camera",
    expected=None,
) -> SeenGrasp:
    """The tool from one frame ``image`` (h, w[, 3]) uint8 taken with the gripper closed on ``task``'s
    fixture at ``joints_deg`` (deg); ``robot`` (calibrated when it is) only predicts where the
    component lies in the frame, within Find points' reach. ``expected``: Find points' modelled view
    (default: the workcell and ``robot`` rendered here). Raises :class:`GraspNotSeenError` naming the
    task when the component's edges do not settle."""
    if task.component is None:
        raise GraspNotSeenError(
            f"task location {task.name!r} names no component: the camera cannot see what the gripper holds"
        )
    item = workcell.component(task.component)
    q = np.asarray(joints_deg, dtype=float)
    cam2base = robot.fk(q, camera_frame)
    view = ModelView(intrinsics) if expected is None else None
    try:
        if view is not None:
            expected = view.of_cell(
                workcell.components, RobotVisuals.from_robot(robot), q, item.item2world, camera_frame
            )
        found = find_points(image, intrinsics, item, concat(item.item2world, invert(cam2base)), expected=expected)
    finally:
        if view is not None:
            view.close()
    if found.edges is None or not found.edges.settled:
        raise GraspNotSeenError(f"the grasp at {task.name!r}: {found.message}")
    solution = edge_solution(found.edges, intrinsics)
    obj2cam = solution.obj2cam
    features = np.array(list(item.features.values()), dtype=float).reshape(-1, 3)
    pose_cov = solution.uncertainty.covariance[:6, :6] + shared_shift_covariance(obj2cam, features, intrinsics)
    tcp2obj = concat(task.tcp2base, invert(item.item2world))
    covariance = tcp_covariance_in_camera(obj2cam, tcp2obj, pose_cov) + np.diag([CENTRING_SIGMA_MM**2] * 3 + [0.0] * 3)
    return SeenGrasp(concat(tcp2obj, obj2cam), covariance, item.name, found.edges.samples)
