"""Collecting board views for the vision-system calibration: each captured image with the robot's
joints when it was taken (or the flange's pose a controller recorded, for a set read from files), detected at once so
the operator sees what each view adds.

The window's Vision mode is a view of this; the same object calibrates the intrinsics and, from the
joints or flange poses, the camera's mounting on the flange.
"""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.robot.model import RobotModel
from calib_core.vision.hand_eye import HandEyeCalibration, calibrate_hand_eye
from calib_core.vision.intrinsics_calibration import (
    BoardView,
    CalibrationInputError,
    IntrinsicsCalibration,
    RejectedView,
    calibrate_intrinsics,
    coverage,
    detect_view,
)


class BoardCapture:
    """Views of one board. ``views`` (accepted, in order) with ``joints_deg`` (the commanded joints
    (6,) deg at each, or ``None`` for a view without a robot pose); ``rejected`` with their reasons."""

    def __init__(self, spec):
        self.spec = spec
        self.views: list[BoardView] = []
        self.joints_deg: list[np.ndarray | None] = []
        self.flange2base: list[np.ndarray | None] = []
        """(4, 4) mm: the flange's pose a controller recorded with the view (a set read from files), else ``None``"""
        self.rejected: list[RejectedView] = []
        self._detector = spec.detector()
        self._count = 0
        self._captured: dict = {}  # frame key -> the view's name

    def add(
        self, image_rgb: np.ndarray, joints_deg=None, frame_key=None, *, flange2base=None, name: str | None = None
    ) -> BoardView | RejectedView:
        """Detect the board in an image and keep the view when enough corners are seen. ``frame_key``
        (hashable: the frame's source and number) refuses a frame captured already: four captures of one
        frame are one view, not four. ``flange2base`` (4, 4) mm: the flange's recorded pose, in place of joints;
        ``name``: the view's (default ``view_NN``)."""
        if frame_key is not None and frame_key in self._captured:
            raise CalibrationInputError(
                f"this frame was captured already ({self._captured[frame_key]}): wait for a new frame from the next "
                "pose"
            )
        if self.views and (image_rgb.shape[1], image_rgb.shape[0]) != self.views[0].image_size:
            w, h = self.views[0].image_size
            raise CalibrationInputError(
                f"this frame is {image_rgb.shape[1]} x {image_rgb.shape[0]} px, the views so far are {w} x {h} px: one "
                "calibration is for one camera mode"
            )
        self._count += 1
        result = detect_view(name or f"view_{self._count:02d}", image_rgb, self.spec, self._detector)
        if frame_key is not None:
            self._captured[frame_key] = result.name
        if isinstance(result, RejectedView):
            self.rejected.append(result)
        else:
            self.views.append(result)
            self.joints_deg.append(None if joints_deg is None else np.array(joints_deg, dtype=float))
            self.flange2base.append(None if flange2base is None else np.array(flange2base, dtype=float))
        return result

    def remove(self, name: str) -> None:
        """Drop an accepted view (a blurred or mis-detected one)."""
        for k, v in enumerate(self.views):
            if v.name == name:
                del self.views[k], self.joints_deg[k], self.flange2base[k]
                return
        raise KeyError(f"no view named {name}; views: {', '.join(v.name for v in self.views) or 'none'}")

    def coverage(self) -> float:
        """Fraction of the image's 8 x 6 cells holding a detected corner (0 without views)."""
        return coverage(self.views, self.views[0].image_size) if self.views else 0.0

    def calibrate_intrinsics(self) -> IntrinsicsCalibration:
        return calibrate_intrinsics(self.views, self.spec, rejected=self.rejected)

    def has_robot_pose(self, k: int) -> bool:
        return self.flange2base[k] is not None or self.joints_deg[k] is not None

    def calibrate_hand_eye(self, robot: RobotModel, intrinsics: Intrinsics) -> HandEyeCalibration:
        """``cam2flange`` from the views taken with a robot pose: the flange's recorded pose, else placed by
        ``robot``'s FK at the view's joints."""
        missing = [v.name for k, v in enumerate(self.views) if not self.has_robot_pose(k)]
        if missing:
            raise CalibrationInputError(
                f"{len(missing)} of {len(self.views)} views have no robot pose (captured without a controller link): "
                + ", ".join(missing[:5])
            )
        flanges = [F if F is not None else robot.fk(q, "flange") for F, q in zip(self.flange2base, self.joints_deg)]
        return calibrate_hand_eye(list(self.views), flanges, self.spec, intrinsics)
