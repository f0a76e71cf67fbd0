"""Where the robot's identification starts the camera's mounting: the cell's, or the one the board views give.

The identification corrects the nominal model by small motions (mm, mrad) and converges to the nearest minimum. A
cell whose camera is modelled far from where it is mounted (a starting cell's guess, a camera turned on its bracket)
starts it in the wrong valley: a real Franka set with a mounting guessed 136 deg off ended at 12.2 px where the same
views give 0.33 px from the right mounting. The board views say where the camera is on its link through the nominal
robot (a hand-eye fit: OpenCV's Park on each view's board pose and the link's pose); the identification starts from
whichever of the two fits the views better, and says when it is not the cell's.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole
from calib_core.frames import concat, invert, make_transform, pose_difference
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.observations import BOARD

MIN_HAND_EYE_VIEWS = 3
"""A hand-eye fit needs at least this many board views (two relative motions about different axes)."""
FAR_MM = 20.0
FAR_DEG = 5.0
"""A cell's mounting within this of the views' (mm, deg) is kept: the hand-eye fit through the nominal robot carries
the robot's own errors (on the simulated cold cells a few mm and tenths of a degree), which the identification then
corrects from the cell's start."""
BETTER_SHARE = 0.5
"""... and one further off is left only when the views' mounting fits them to under this share of the cell's RMS."""


@dataclass(frozen=True)
class MountingStart:
    """``robot`` the model to start from (the given one, or a copy with the camera's mounting from the views);
    ``note`` what was changed and why (``None`` when the cell's mounting was kept)."""

    robot: RobotModel
    note: str | None = None


def mounting_from_views(
    robot: RobotModel, intrinsics: Intrinsics, views: list, camera_frame: str = "camera"
) -> np.ndarray | None:
    """The camera frame's placement (4, 4, mm) on its parent joint that the board ``views`` give through ``robot``'s
    nominal kinematics (a hand-eye fit), or ``None`` with fewer than :data:`MIN_HAND_EYE_VIEWS` views of the board."""
    placement = robot.frame_placement(camera_frame)
    links, boards = [], []
    for v in views:
        if v.target != BOARD or len(v.points_mm) < 4:
            continue
        pixels, camera = as_pinhole(v.pixels, intrinsics)  # OpenCV's PnP knows no fisheye lens
        ok, rvec, tvec = cv2.solvePnP(v.points_mm, pixels, camera.K, camera.dist_coeffs, flags=cv2.SOLVEPNP_ITERATIVE)
        if not ok:
            continue
        # the camera's parent joint in the base: wherever the camera is modelled on it, the same pose
        links.append(concat(invert(placement), robot.fk(v.joints_deg, camera_frame)))  # joint2cam, cam2base
        boards.append(make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel()))
    if len(links) < MIN_HAND_EYE_VIEWS:
        return None
    R, t = cv2.calibrateHandEye(
        [L[:3, :3] for L in links],
        [L[:3, 3] for L in links],
        [B[:3, :3] for B in boards],
        [B[:3, 3] for B in boards],
        method=cv2.CALIB_HAND_EYE_PARK,
    )
    if not (np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
        return None
    return make_transform(R, np.asarray(t, dtype=float).ravel())


def mounting_start(
    robot: RobotModel,
    intrinsics: Intrinsics,
    views: list,
    camera_frame: str,
    start_rms_px,
) -> MountingStart:
    """The model the identification starts from: ``robot`` as given, or a copy with the camera's mounting from
    :func:`mounting_from_views` when that fits the views better. ``start_rms_px(model)`` is the RMS (px) of the views
    through ``model`` with no correction (``inf`` where points fall behind the camera)."""
    found = mounting_from_views(robot, intrinsics, views, camera_frame)
    if found is None:
        return MountingStart(robot)
    moved = robot.copy()
    moved.set_frame_placement(camera_frame, found)
    d_mm, r_deg = pose_difference(found, robot.frame_placement(camera_frame))
    if np.linalg.norm(d_mm) < FAR_MM and np.linalg.norm(r_deg) < FAR_DEG:
        return MountingStart(robot)  # near: the identification's small corrections reach it from the cell's
    given_px, found_px = start_rms_px(robot), start_rms_px(moved)
    if not found_px < BETTER_SHARE * given_px:
        return MountingStart(robot)
    return MountingStart(
        moved,
        f"the cell's camera mounting lies {np.linalg.norm(d_mm):.0f} mm and {np.linalg.norm(r_deg):.0f} "
        f"deg from where the board views put it (a hand-eye fit through the nominal robot: RMS {found_px:.1f} px "
        f"against {given_px:.1f} px from the cell's): the identification started from the views' mounting; put the "
        "calibrated one into the cell (robot: frames: camera)",
    )
