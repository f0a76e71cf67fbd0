"""The camera pane: live or recorded video, a cross-hair pixel picker with optional sub-pixel
refinement, freezing, and the overlays that show the fit after a solve."""

from __future__ import annotations

import cv2
import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QCheckBox, QHBoxLayout, QLabel, QSlider, QVBoxLayout, QWidget

from app.gui.image_view import ImageView, Overlay
from app.gui.workbench import Workbench
from calib_core.camera.projection import project_points
from calib_core.frames import apply, invert

PICK_COLOR = QColor(255, 214, 10)
PENDING_COLOR = QColor(255, 140, 0)
REPROJECTED_COLOR = QColor(0, 220, 255)
RESIDUAL_COLOR = QColor(255, 70, 70)
RESIDUAL_SCALE = 10.0
GHOST_COLOR = QColor(255, 60, 220)
BOARD_COLOR = QColor(60, 230, 90)


def refine_subpixel(image_rgb: np.ndarray, u: float, v: float, half_window: int = 5, max_shift_px: float = 2.0) -> tuple[float, float]:
    """The corner nearest (u, v) to sub-pixel accuracy (``cv2.cornerSubPix``); the click itself
    when the refinement wanders further than ``max_shift_px`` (no corner there: a circle centre,
    a flat patch), since the operator's click is then the better estimate."""
    grey = cv2.cvtColor(image_rgb, cv2.COLOR_RGB2GRAY).astype(np.float32)
    corner = np.array([[[u, v]]], dtype=np.float32)
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 40, 0.01)
    try:
        refined = cv2.cornerSubPix(grey, corner, (half_window, half_window), (-1, -1), criteria)[0, 0]
    except cv2.error:  # a click too near the border for the search window
        return u, v
    if np.hypot(refined[0] - u, refined[1] - v) > max_shift_px:
        return u, v
    return float(refined[0]), float(refined[1])


class CameraPane(QWidget):
    """Shows frames; ``picked(u, v)`` when the operator picks a pixel (refined if asked)."""

    picked = Signal(float, float)
    pick_rejected = Signal(str)  # a click that picks nothing, and why

    def __init__(self, workbench: Workbench, parent=None):
        super().__init__(parent)
        self.workbench = workbench
        self.view = ImageView(placeholder="waiting for the camera...", loupe=True)
        self.freeze = QCheckBox("Freeze")
        self.freeze.setToolTip("Hold the current frame while picking")
        self.subpixel = QCheckBox("Sub-pixel")
        self.subpixel.setChecked(True)
        self.subpixel.setToolTip("Refine each pick to the nearest corner (cv2.cornerSubPix)")
        self.edges = QCheckBox("CAD edges")
        self.edges.setToolTip("After a solve, draw the model's edges from the measured camera pose")
        self.edges.setChecked(True)
        self.opacity = QSlider(Qt.Orientation.Horizontal)
        self.opacity.setRange(0, 100)
        self.opacity.setValue(70)
        self.opacity.setMaximumWidth(90)
        self.info = QLabel("")
        self.info.setStyleSheet("color: #9aa;")
        bar = QHBoxLayout()
        for w in (QLabel("<b>Camera</b>"), self.freeze, self.subpixel, self.edges, self.opacity):
            bar.addWidget(w)
        bar.addStretch(1)
        bar.addWidget(self.info)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addLayout(bar)
        layout.addWidget(self.view, 1)
        self.last_frame = None  # the frame shown (held while frozen)
        self.last_frame_received = None  # the newest frame from the source, shown or not
        self._board_corners: np.ndarray | None = None  # a board detection shown by the Vision mode
        self._board_text = ""
        self._edges_image: np.ndarray | None = None
        self.view.clicked.connect(self._on_click)
        self.edges.toggled.connect(lambda _: self.refresh_overlay())
        self.opacity.valueChanged.connect(lambda _: self.refresh_overlay())
        workbench.session.pairs.changed.connect(lambda *_: self.refresh_overlay())
        workbench.session.changed.connect(self._on_solved)

    def show_frame(self, frame) -> None:
        self.last_frame_received = frame
        if self.freeze.isChecked() and self.last_frame is not None:
            return
        self.last_frame = frame
        self.view.set_image(frame.image)

    def _on_click(self, u: float, v: float) -> None:
        if self.last_frame is None:
            self.pick_rejected.emit("no camera image yet: start the camera (Execute > Live) or open a recording")
            return
        h, w = self.last_frame.image.shape[:2]
        if not (-0.5 <= u < w - 0.5 and -0.5 <= v < h - 0.5):
            self.pick_rejected.emit(f"the click at ({u:.1f}, {v:.1f}) px is outside the camera image ({w} x {h} px): nothing picked")
            return
        if self.subpixel.isChecked():
            u, v = refine_subpixel(self.last_frame.image, u, v)
        self.picked.emit(u, v)

    def set_board_corners(self, corners_px: np.ndarray | None, text: str = "") -> None:
        """Show a board detection (n, 2) px over the image (``None`` hides it)."""
        self._board_corners = None if corners_px is None else np.asarray(corners_px, dtype=float)
        self._board_text = text
        self.refresh_overlay()

    def set_edges_image(self, rgba: np.ndarray | None) -> None:
        self._edges_image = rgba
        self.refresh_overlay()

    def _on_solved(self) -> None:
        self.refresh_overlay()

    def refresh_overlay(self) -> None:
        session = self.workbench.session
        overlay = Overlay()
        pending = session.pairs.pending()
        for pair in session.pairs:
            if pair.pixel is not None:
                color = PICK_COLOR if pair.enabled else QColor(130, 130, 130)
                overlay.points.append((pair.pixel[0], pair.pixel[1], str(pair.number), color))
        result = session.result
        if result is not None:
            obj2cam = invert(result.cam2world_measured) @ result.obj2world
            for pair in session.pairs:
                if pair.pixel is None:
                    continue
                p_obj = apply(invert(result.obj2world), np.array(pair.point_world_mm)[None])
                uv = project_points(p_obj, obj2cam, self.workbench.intrinsics)[0]
                if np.all(np.isfinite(uv)):
                    overlay.points.append((uv[0], uv[1], "", REPROJECTED_COLOR))
                    end = np.array(pair.pixel) + RESIDUAL_SCALE * (np.array(pair.pixel) - uv)
                    overlay.segments.append((uv[0], uv[1], end[0], end[1], RESIDUAL_COLOR))
            overlay.text = f"cyan: model points from the solved pose; red: residuals x{RESIDUAL_SCALE:g}"
            candidates = result.solution.candidates
            if len(candidates) > 1:
                # Ghosts of the other poses that fit as well, so the operator can tell them apart.
                for k, candidate in enumerate(candidates):
                    if k == session.chosen_candidate:
                        continue
                    for pair in session.pairs:
                        p_obj = apply(invert(result.obj2world), np.array(pair.point_world_mm)[None])
                        uv = project_points(p_obj, candidate.obj2cam, self.workbench.intrinsics)[0]
                        if np.all(np.isfinite(uv)):
                            overlay.points.append((uv[0], uv[1], f"s{k + 1}", GHOST_COLOR))
                overlay.text = f"{len(candidates)} poses fit: magenta ghosts show the others; choose one in Results"
            if self.edges.isChecked() and self._edges_image is not None:
                overlay.image = self._edges_image
                overlay.image_opacity = self.opacity.value() / 100.0
        if pending is not None:
            overlay.text = f"pick point {pending.number} ({pending.feature or 'surface point'}) on the camera image"
        if self._board_corners is not None:
            for u, v in self._board_corners:
                overlay.points.append((u, v, "", BOARD_COLOR))
            overlay.text = self._board_text
        self.view.set_overlay(overlay)
