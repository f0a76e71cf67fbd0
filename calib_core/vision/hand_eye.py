"""The camera's mounting on the flange (``cam2flange``) from robot poses looking at a ChArUco board.

OpenCV's ``calibrateHandEye`` (Tsai, Park, Daniilidis...) gives a start from the per-view board poses;
then the reprojection error of every corner in every view is minimised over ``cam2flange`` and the
board's placement together (``scipy.optimize.least_squares``), with the robot's forward kinematics
taken as exact. Uncertainty comes from the Jacobian at the optimum. Poor pose sets (too little
rotation, rotations about parallel axes) are reported.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, invert, make_transform
from calib_core.vision.board import BoardSpec
from calib_core.vision.intrinsics_calibration import BoardView, CalibrationInputError

MIN_POSES = 3
_MIN_ROTATION_DEG = 10.0


@dataclass(frozen=True)
class HandEyeCalibration:
    """``cam2flange`` (4, 4) mm with 1-sigma ``std_xyz_mm`` (3,) and ``std_rotation_deg`` (3,);
    ``board2base`` (4, 4) mm; ``rms_px`` of all corners; ``start`` the closed-form estimate;
    ``warnings`` about the pose set."""

    cam2flange: np.ndarray
    std_xyz_mm: np.ndarray
    std_rotation_deg: np.ndarray
    board2base: np.ndarray
    rms_px: float
    start: np.ndarray
    views: int
    warnings: list[str] = field(default_factory=list)


def board_pose(view: BoardView, spec: BoardSpec, intrinsics: Intrinsics) -> np.ndarray:
    """``board2cam`` (4, 4) mm of one view (OpenCV's PnP on the detected corners)."""
    obj = spec.corners_mm()[view.ids]
    ok, rvec, tvec = cv2.solvePnP(obj, view.corners_px, intrinsics.K, intrinsics.dist_coeffs, flags=cv2.SOLVEPNP_ITERATIVE)
    if not ok:
        raise CalibrationInputError(f"view {view.name}: the board's pose could not be found")
    return make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel())


def pose_set_warnings(flange2base: list[np.ndarray]) -> list[str]:
    """Hand-eye needs rotations of some size about at least two non-parallel axes."""
    axes, angles = [], []
    for i in range(len(flange2base)):
        for j in range(i + 1, len(flange2base)):
            rel = Rotation.from_matrix(flange2base[i][:3, :3].T @ flange2base[j][:3, :3]).as_rotvec()
            angle = np.linalg.norm(rel)
            angles.append(np.degrees(angle))
            if angle > np.radians(2.0):
                axes.append(rel / angle)
    out = []
    if not angles or max(angles) < _MIN_ROTATION_DEG:
        out.append(f"the poses rotate the tool by at most {max(angles, default=0):.1f} deg: rotate 20-40 deg between poses")
    if len(axes) >= 2:
        s = np.linalg.svd(np.array(axes), compute_uv=False)
        if s[1] < 0.2 * s[0]:
            out.append("the rotations between poses are about nearly parallel axes: the mounting is then undetermined along that axis; tilt about two different axes")
    elif angles:
        out.append("too few rotations between poses to determine the mounting")
    return out


def calibrate_hand_eye(views: list[BoardView], flange2base: list[np.ndarray], spec: BoardSpec, intrinsics: Intrinsics, *, method: int = cv2.CALIB_HAND_EYE_PARK) -> HandEyeCalibration:
    """``views[i]`` seen with the flange at ``flange2base[i]`` (4, 4, mm, from forward kinematics)."""
    if len(views) != len(flange2base):
        raise CalibrationInputError(f"{len(views)} views but {len(flange2base)} robot poses: every view needs the pose it was taken at")
    if len(views) < MIN_POSES:
        raise CalibrationInputError(f"{len(views)} poses, at least {MIN_POSES} needed (10 or more recommended)")
    warnings = pose_set_warnings(flange2base)
    board2cam = [board_pose(v, spec, intrinsics) for v in views]
    R_cam2flange, t_cam2flange = cv2.calibrateHandEye(
        [T[:3, :3] for T in flange2base], [T[:3, 3] for T in flange2base],
        [T[:3, :3] for T in board2cam], [T[:3, 3] for T in board2cam], method=method,
    )
    start = make_transform(R_cam2flange, np.asarray(t_cam2flange).ravel())
    # The board's placement from the start: average over views of flange2base . cam2flange . board2cam.
    placements = [F @ start @ B for F, B in zip(flange2base, board2cam)]
    board2base0 = make_transform(Rotation.from_matrix([P[:3, :3] for P in placements]).mean().as_matrix(), np.mean([P[:3, 3] for P in placements], axis=0))
    corners = spec.corners_mm()

    def unpack(x):
        return make_transform(Rotation.from_rotvec(x[:3]).as_matrix(), x[3:6]), make_transform(Rotation.from_rotvec(x[6:9]).as_matrix(), x[9:12])

    def residuals(x):
        cam2flange, board2base = unpack(x)
        out = []
        for v, F in zip(views, flange2base):
            board2cam_i = invert(cam2flange) @ invert(F) @ board2base
            out.append((project(apply(board2cam_i, corners[v.ids]), intrinsics) - v.corners_px).ravel())
        return np.concatenate(out)

    x0 = np.concatenate([Rotation.from_matrix(start[:3, :3]).as_rotvec(), start[:3, 3], Rotation.from_matrix(board2base0[:3, :3]).as_rotvec(), board2base0[:3, 3]])
    fit = least_squares(residuals, x0, method="lm", x_scale=np.r_[[0.01] * 3, [1.0] * 3, [0.01] * 3, [1.0] * 3])
    cam2flange, board2base = unpack(fit.x)
    r = fit.fun
    dof = max(len(r) - 12, 1)
    sigma2 = float(r @ r) / dof
    J = fit.jac
    try:
        cov = sigma2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        cov = np.full((12, 12), np.inf)
        warnings.append("the pose set does not determine the mounting (singular normal equations)")
    std = np.sqrt(np.clip(np.diag(cov), 0, None))
    rms = float(np.sqrt(np.mean(r**2) * 2))
    if rms > 1.0:
        warnings.append(f"the views do not agree on one mounting (RMS {rms:.1f} px): hand-eye calibration takes the robot's forward kinematics as exact, and this robot's is not accurate enough; calibrate the robot first, or use poses close together")
    return HandEyeCalibration(cam2flange, std[3:6], np.degrees(std[:3]), board2base, rms, start, len(views), warnings)
