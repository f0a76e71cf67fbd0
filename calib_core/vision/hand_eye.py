"""The camera's mounting from robot poses and views of a calibration board.

Camera on the robot (the usual case here): the result is ``cam2flange`` and where the board stands,
``board2base``. Camera fixed in the cell, board held by the robot (``static_camera=True``,
ROS-Industrial's ``static_camera``): ``cam2base`` and ``board2flange``. Both are one problem: with
``A`` the flange's pose, the board is seen at ``X^-1 A^-1 Y`` (camera on the robot) or ``X^-1 A Y``
(camera fixed), so the second is the first with ``A`` inverted (what OpenCV's documentation says
for ``calibrateHandEye`` too).

OpenCV's ``calibrateHandEye`` (Park) gives a start from the per-view board poses; then the
reprojection error of every corner in every view is minimised over ``X`` and ``Y`` together
(``scipy.optimize.least_squares``), with the robot's forward kinematics taken as exact. Uncertainty
comes from the Jacobian at the optimum. Poor pose sets (too little rotation, rotations about parallel
axes) are reported, and so are views that disagree beyond what the corners' own noise explains.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole, project
from calib_core.frames import apply, concat, invert, make_transform
from calib_core.solver.clustered_covariance import clustered_scatter
from calib_core.vision.target_spec import turn_ambiguity
from calib_core.vision.intrinsics_calibration import BoardView, CalibrationInputError

MIN_POSES = 3
_MIN_ROTATION_DEG = 10.0
POSE_SIGMA_MM = 1.0
"""How well an uncalibrated industrial robot's poses are known, 1-sigma per axis, mm (its absolute
accuracy is 1-3 mm; poses close together agree better)."""


@dataclass(frozen=True)
class HandEyeCalibration:
    """``camera2mount`` (4, 4) mm, the camera in what holds it (the flange, or the robot's base for a
    static camera), with 1-sigma ``std_xyz_mm`` (3,) and ``std_rotation_deg`` (3,); ``board2mount``
    (4, 4) mm the board in what holds it (the base, or the flange); ``rms_px`` of all corners;
    ``noise_px`` the corners' own noise (the RMS of each view's board pose fitted alone); ``start``
    the closed-form estimate; ``warnings`` about the pose set and the fit."""

    camera2mount: np.ndarray
    std_xyz_mm: np.ndarray
    std_rotation_deg: np.ndarray
    board2mount: np.ndarray
    rms_px: float
    start: np.ndarray
    views: int
    warnings: list[str] = field(default_factory=list)
    static_camera: bool = False
    noise_px: float = float("nan")
    per_view_rms_px: tuple[float, ...] = ()
    poses: "PoseAgreement | None" = None
    """How well the robot's poses agree with one another through this answer."""

    def _mobile(self, name: str, value: np.ndarray) -> np.ndarray:
        if self.static_camera:
            raise ValueError(f"{name}: this result is for a static camera (cam2base and board2flange)")
        return value

    def _static(self, name: str, value: np.ndarray) -> np.ndarray:
        if not self.static_camera:
            raise ValueError(f"{name}: this result is for a camera on the robot (cam2flange and board2base)")
        return value

    @property
    def cam2flange(self) -> np.ndarray:
        return self._mobile("cam2flange", self.camera2mount)

    @property
    def board2base(self) -> np.ndarray:
        return self._mobile("board2base", self.board2mount)

    @property
    def cam2base(self) -> np.ndarray:
        return self._static("cam2base", self.camera2mount)

    @property
    def board2flange(self) -> np.ndarray:
        return self._static("board2flange", self.board2mount)


def board_pose(view: BoardView, spec, intrinsics: Intrinsics) -> np.ndarray:
    """``board2cam`` (4, 4) mm of one view (OpenCV's PnP on the detected corners)."""
    return board_pose_fit(view, spec, intrinsics)[0]


def board_pose_fit(view: BoardView, spec, intrinsics: Intrinsics) -> tuple[np.ndarray, float]:
    """``board2cam`` (4, 4) mm of one view and the RMS distance (px) of its corners from their reprojection."""
    obj = spec.corners_mm()[view.ids]
    pixels, camera = as_pinhole(view.corners_px, intrinsics)  # OpenCV's PnP knows no fisheye lens
    ok, rvec, tvec = cv2.solvePnP(obj, pixels, camera.K, camera.dist_coeffs, flags=cv2.SOLVEPNP_ITERATIVE)
    if not ok:
        raise CalibrationInputError(f"view {view.name}: the board's pose could not be found")
    pose = make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel())
    r = project(apply(pose, obj), intrinsics) - view.corners_px
    return pose, float(np.sqrt(2.0 * np.mean(r**2)))


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
        out.append(
            f"the poses rotate the tool by at most {max(angles, default=0):.1f} deg: rotate 20-40 deg between poses"
        )
    if len(axes) >= 2:
        s = np.linalg.svd(np.array(axes), compute_uv=False)
        if s[1] < 0.2 * s[0]:
            out.append(
                "the rotations between poses are about nearly parallel axes: the mounting is then undetermined along "
                "that axis; tilt about two different axes"
            )
    elif angles:
        out.append("too few rotations between poses to determine the mounting")
    return out


def calibrate_hand_eye(
    views: list[BoardView],
    flange2base: list[np.ndarray],
    spec,
    intrinsics: Intrinsics,
    *,
    static_camera: bool = False,
    pose_sigma_mm: float = POSE_SIGMA_MM,
    method: int = cv2.CALIB_HAND_EYE_PARK,
) -> HandEyeCalibration:
    """``views[i]`` seen with the flange at ``flange2base[i]`` (4, 4, mm, from forward kinematics or
    the controller). ``static_camera``: the camera stands in the cell and the robot holds the board.
    ``pose_sigma_mm``: how well the robot's poses are known (1-sigma per axis), which with the corners'
    measured noise sets when the views are said to disagree."""
    if len(views) != len(flange2base):
        raise CalibrationInputError(
            f"{len(views)} views but {len(flange2base)} robot poses: every view needs the pose it was taken at"
        )
    if len(views) < MIN_POSES:
        raise CalibrationInputError(f"{len(views)} poses, at least {MIN_POSES} needed (10 or more recommended)")
    if not spec.unambiguous:
        raise CalibrationInputError(turn_ambiguity(spec, "the camera's mounting"))
    warnings = pose_set_warnings(flange2base)
    # The camera on the robot sees the board at X^-1 A^-1 Y; a static camera at X^-1 A Y.
    moving = [invert(T) for T in flange2base] if static_camera else [np.asarray(T, dtype=float) for T in flange2base]
    fits = [board_pose_fit(v, spec, intrinsics) for v in views]
    board2cam = [pose for pose, _ in fits]
    noise = float(np.sqrt(np.mean([e**2 for _, e in fits])))
    cam2flange, board2base, start, r, J = _fit(views, moving, board2cam, spec, intrinsics, static_camera, method)
    dof = max(len(r) - 12, 1)
    sigma2 = float(r @ r) / dof
    # Each view's corners share that view's robot pose error: taken as independent, 400 corners a view would claim
    # a tenth of the real 1-sigma (a real KUKA set: 0.01-0.04 mm stated, where leaving a third of the views out moves
    # the answer by tenths of a millimetre). Each view's summed score counts as one measurement (cluster-robust).
    groups = np.repeat(np.arange(len(views)), [2 * len(v.ids) for v in views])
    try:
        H_inv = np.linalg.inv(J.T @ J)
        cov = H_inv @ clustered_scatter(J, r, groups, sigma2 * (J.T @ J)) @ H_inv * _few_views_factor(len(views))
    except np.linalg.LinAlgError:
        cov = np.full((12, 12), np.inf)
        warnings.append("the pose set does not determine the mounting (singular normal equations)")
    std = np.sqrt(np.clip(np.diag(cov), 0, None))
    rms, per_view = _rms(r, views)
    agreement = pose_agreement(moving, cam2flange, board2cam, [v.name for v in views])
    if rms > BEYOND_NOISE * noise:
        warnings.append(
            f"the views disagree beyond the corners' noise (RMS {rms:.2f} px against {noise:.2f} px): the robot's "
            f"poses agree to {agreement.spread_mm:.2f} mm / {agreement.spread_deg:.3f} deg (the board's place in the "
            f"{'flange' if static_camera else 'base'} from each view, RMS), and the 1-sigma includes that; the views "
            f"that disagree most: {', '.join(agreement.worst)}"
        )
    distance_mm = float(np.median([np.linalg.norm(B[:3, 3]) for B in board2cam]))
    pose_px = 0.5 * (intrinsics.fu + intrinsics.fv) * pose_sigma_mm / max(distance_mm, 1.0)
    limit = disagreement_limit_px(noise, pose_px)
    if rms > limit:
        warnings.append(
            f"the views do not agree on one mounting (RMS {rms:.2f} px, over the {limit:.2f} px that the corners' "
            f"noise of {noise:.2f} px "
            f"and robot poses good to {pose_sigma_mm:g} mm at {distance_mm:.0f} mm explain): hand-eye calibration "
            "takes the robot's poses as exact, and these are not accurate enough; "
            "calibrate the robot first, or use poses close together"
        )
        # One bad pose pulls every view: name it when leaving it out makes the rest agree.
        if len(views) > MIN_POSES + 1:
            worst = int(np.argmax(per_view))
            keep = [k for k in range(len(views)) if k != worst]
            try:
                *_, r_rest, _ = _fit(
                    [views[k] for k in keep],
                    [moving[k] for k in keep],
                    [board2cam[k] for k in keep],
                    spec,
                    intrinsics,
                    static_camera,
                    method,
                )
            except CalibrationInputError:
                r_rest = None
            if r_rest is not None and _rms(r_rest, [views[k] for k in keep])[0] <= limit:
                warnings.append(
                    f"view {views[worst].name} disagrees with the others: without it the RMS is "
                    f"{_rms(r_rest, [views[k] for k in keep])[0]:.2f} px; "
                    "a wrong robot pose for it, or the board moved: remove it"
                )
    return HandEyeCalibration(
        cam2flange,
        std[3:6],
        np.degrees(std[:3]),
        board2base,
        rms,
        start,
        len(views),
        warnings,
        static_camera,
        noise,
        per_view,
        agreement,
    )


BEYOND_NOISE = 3.0
"""Views whose corners' RMS is over this many times the corners' own noise disagree: the poses are said."""


def _few_views_factor(views: int) -> float:
    """The cluster-robust covariance's small-sample correction for ``views`` clusters and the mounting's 6 unknowns
    (G / (G - 6), CR1 with the parameters a cluster informs): with 12 views it doubles the variance."""
    return views / max(views - 6, 1)


@dataclass(frozen=True)
class PoseAgreement:
    """How well the robot's recorded poses agree with one another, seen through the answer: the board's place in its
    mount predicted from each view (``flange2base . cam2flange . board2cam``); ``spread_mm`` and ``spread_deg`` the RMS
    of its translations and turns about their mean; ``per_view_mm`` each view's distance from the mean; ``worst`` the
    three views furthest from it, by name."""

    spread_mm: float
    spread_deg: float
    per_view_mm: tuple[float, ...]
    worst: tuple[str, ...]


def pose_agreement(moving, camera2mount: np.ndarray, board2cam, names) -> PoseAgreement:
    """:class:`PoseAgreement` of the views whose mounts are at ``moving`` (4, 4, mm each), seen at ``board2cam``."""
    placed = [concat(B, camera2mount, F) for F, B in zip(moving, board2cam)]  # board2cam, cam2flange, flange2base
    t = np.array([P[:3, 3] for P in placed])
    mean_turn = Rotation.from_matrix([P[:3, :3] for P in placed]).mean()
    turns = np.degrees((Rotation.from_matrix([P[:3, :3] for P in placed]) * mean_turn.inv()).magnitude())
    apart = np.linalg.norm(t - t.mean(axis=0), axis=1)
    worst = tuple(names[k] for k in np.argsort(-apart)[:3])
    return PoseAgreement(
        float(np.sqrt(np.mean(apart**2))), float(np.sqrt(np.mean(turns**2))), tuple(float(a) for a in apart), worst
    )


def _rms(r: np.ndarray, views: list[BoardView]) -> tuple[float, tuple[float, ...]]:
    """RMS distance (px) of all corners and of each view's, from the residual vector ``r``."""
    bounds = np.cumsum([0] + [2 * len(v.ids) for v in views])
    per_view = tuple(float(np.sqrt(2.0 * np.mean(r[a:b] ** 2))) for a, b in zip(bounds[:-1], bounds[1:]))
    return float(np.sqrt(2.0 * np.mean(r**2))), per_view


def _fit(views, moving, board2cam, spec, intrinsics, static_camera, method):
    """``X`` (camera in its mount), ``Y`` (board in its mount), the closed-form start, the residuals
    (px) and their Jacobian at the optimum."""
    try:
        R_cam2flange, t_cam2flange = cv2.calibrateHandEye(
            [T[:3, :3] for T in moving],
            [T[:3, 3] for T in moving],
            [T[:3, :3] for T in board2cam],
            [T[:3, 3] for T in board2cam],
            method=method,
        )
    except cv2.error:
        other = (
            "is the camera on the robot?" if static_camera else "is it a static camera (the robot holding the board)?"
        )
        raise CalibrationInputError(
            "the robot poses and the board views fit no "
            f"{'static camera' if static_camera else 'camera on the robot'}: {other} "
            "Are the poses the flange's in the base, in the views' order?"
        ) from None
    if not np.all(np.isfinite(R_cam2flange)) or abs(np.linalg.det(R_cam2flange) - 1.0) > 1e-3:
        raise CalibrationInputError(
            "the robot poses and the board views give no rotation for the camera's mounting: are the poses the "
            "flange's in the base, in the views' order?"
        )
    start = make_transform(R_cam2flange, np.asarray(t_cam2flange).ravel())
    # The board's placement from the start: average over views of flange2base . cam2flange . board2cam.
    placements = [concat(B, start, F) for F, B in zip(moving, board2cam)]
    board2base0 = make_transform(
        Rotation.from_matrix([P[:3, :3] for P in placements]).mean().as_matrix(),
        np.mean([P[:3, 3] for P in placements], axis=0),
    )
    corners = spec.corners_mm()

    def unpack(x):
        return make_transform(Rotation.from_rotvec(x[:3]).as_matrix(), x[3:6]), make_transform(
            Rotation.from_rotvec(x[6:9]).as_matrix(), x[9:12]
        )

    def residuals(x):
        cam2flange, board2base = unpack(x)
        out = []
        for v, F in zip(views, moving):
            board2cam_i = concat(board2base, invert(F), invert(cam2flange))
            out.append((project(apply(board2cam_i, corners[v.ids]), intrinsics) - v.corners_px).ravel())
        return np.concatenate(out)

    x0 = np.concatenate(
        [
            Rotation.from_matrix(start[:3, :3]).as_rotvec(),
            start[:3, 3],
            Rotation.from_matrix(board2base0[:3, :3]).as_rotvec(),
            board2base0[:3, 3],
        ]
    )
    fit = least_squares(residuals, x0, method="lm", x_scale=np.r_[[0.01] * 3, [1.0] * 3, [0.01] * 3, [1.0] * 3])
    cam2flange, board2base = unpack(fit.x)
    return cam2flange, board2base, start, fit.fun, fit.jac


def disagreement_limit_px(noise_px: float, pose_px: float) -> float:
    """The RMS distance (px) above which views are said to disagree on one mounting: three sigma of
    the corners' noise ``noise_px`` (a distance) and of the robot's pose error seen in the image,
    ``pose_px`` per axis (so sqrt(2) of it as a distance). Both scale with the camera's resolution."""
    return 3.0 * float(np.hypot(noise_px, np.sqrt(2.0) * pose_px))
