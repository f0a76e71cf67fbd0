"""The camera pane: live or recorded video, a cross-hair pixel picker with optional sub-pixel
refinement, freezing, and the overlays that show the fit after a solve."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QCheckBox, QHBoxLayout, QLabel, QSlider, QVBoxLayout, QWidget

from app.gui.error_boundary import attempt
from app.gui.image_view import ImageView, Overlay
from app.gui.solved_edges import SolvedEdges
from calib_core.operator.panes.camera import CameraPaneModel
from calib_core.calibration.view_stamp import SAME_STATE_DEG
from calib_core.camera.projection import project_points
from calib_core.errors import OperatorError
from calib_core.frames import apply, concat, invert

PICK_COLOR = QColor(255, 214, 10)
PENDING_COLOR = QColor(255, 140, 0)
REPROJECTED_COLOR = QColor(0, 220, 255)
RESIDUAL_COLOR = QColor(255, 70, 70)
RESIDUAL_SCALE = 10.0
GHOST_COLOR = QColor(255, 60, 220)
BOARD_COLOR = QColor(60, 230, 90)
PROPOSAL_COLOR = QColor(80, 200, 255)
EXPECTED_COLOR = QColor(255, 255, 255)
STALE_COLOR = QColor(120, 120, 120)


class CameraPane(QWidget):
    """Shows the core's frames; a click picks the waiting pair's image point in the core (refined if
    asked), a drag moves a pair's point; ``pick_rejected(text)`` says why a click picked nothing.

    Picks are made on a still: the core holds a frame at the first image pick of a set (``Hold``
    shows it; unticking it goes back to the live image) and the live video goes on in the corner.
    What is drawn belongs to a robot state: picks and results made at another pose than the one
    the image shows are greyed or hidden, with a banner that says so."""

    pick_rejected = Signal(str)  # a click or a drag that picks nothing, and why
    pair_selected = Signal(int)  # a click on a pair's point

    def __init__(self, model: CameraPaneModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.view = ImageView(placeholder="waiting for the camera...", loupe=True)
        self.view.grabber = self._grab
        self.view.dragged.connect(self._dragging)
        self.view.drag_finished.connect(self._dropped)
        self._grabbed: int | None = None
        self._proposals: list | None = None
        self._proposal_joints: np.ndarray | None = None
        self._drag_at: tuple[float, float] | None = None
        self.freeze = QCheckBox("Hold")
        self.freeze.setToolTip(
            "Pick on a still: the frame is held (only when the robot had settled) and the live video goes on in the "
            "corner"
        )
        self.subpixel = QCheckBox("Sub-pixel")
        self.subpixel.setChecked(True)
        self.subpixel.setToolTip(
            "Refine each pick: a round feature to the centre of its rim, anything else to the nearest corner "
            "(cv2.cornerSubPix)"
        )
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
        self.last_frame = None  # the frame shown (the held one while a still is held)
        self.last_frame_received = None  # the newest frame from the source, shown or not
        self._board_corners: np.ndarray | None = None  # a board detection shown by the Vision mode
        self._board_joints: np.ndarray | None = None  # the robot state it was detected at
        self._board_text = ""
        self._edges_image: np.ndarray | None = None
        self.solved_edges = SolvedEdges(model.intrinsics)
        self.edges_drawn = 0  # the solves whose CAD edges were drawn (tests and the bench wait on it)
        self._drawn_state: tuple | None = None
        self.view.clicked.connect(self._on_click)
        self.freeze.toggled.connect(self._hold_toggled)
        self.edges.toggled.connect(lambda _: self.refresh_overlay())
        self.opacity.valueChanged.connect(lambda _: self.refresh_overlay())
        model.frame_observed.connect(self.show_frame)
        model.still_changed.connect(self._still_changed)
        model.pairs_changed.connect(lambda *_: self.refresh_overlay())
        model.result_changed.connect(self._on_solved)
        model.joints_changed.connect(self._joints_changed)
        model.camera_model_changed.connect(lambda: self.solved_edges.set_intrinsics(self.model.intrinsics))
        model.points_found.connect(self._points_found)

    # --- frames ---------------------------------------------------------------------------------
    @property
    def held(self):
        return self.model.still

    def show_frame(self, frame) -> None:
        self.last_frame_received = frame
        if self.held is not None:
            self.view.set_inset(frame.image, "live")
            return
        self.last_frame = frame
        self.view.set_image(frame.image)

    def _hold_toggled(self, on: bool) -> None:
        if on and self.held is None:
            try:
                self.model.hold_frame()
            except OperatorError as exc:
                self.freeze.blockSignals(True)
                self.freeze.setChecked(False)
                self.freeze.blockSignals(False)
                self.pick_rejected.emit(str(exc))
        elif not on and self.held is not None:
            self.model.release_frame()

    def _still_changed(self, held) -> None:
        self.freeze.blockSignals(True)
        self.freeze.setChecked(held is not None)
        self.freeze.blockSignals(False)
        if held is not None:
            self.last_frame = held.frame
            self.view.set_image(held.frame.image)
            self.info.setText(f"held: frame {held.stamp.frame_index}")
        else:
            self.view.set_inset(None)
            self.info.setText("")
            if self.last_frame_received is not None:
                self.last_frame = self.last_frame_received
                self.view.set_image(self.last_frame.image)
        self.refresh_overlay()

    def _on_click(self, u: float, v: float) -> None:
        if self.last_frame is None:
            self.pick_rejected.emit("no camera image yet: start the camera (Execute > Live) or open a recording")
            return
        h, w = self.last_frame.image.shape[:2]
        if not (-0.5 <= u < w - 0.5 and -0.5 <= v < h - 0.5):
            self.pick_rejected.emit(
                f"the click at ({u:.1f}, {v:.1f}) px is outside the camera image ({w} x {h} px): nothing picked"
            )
            return
        # The core holds the newest frame at the first pick of a set and refines on it.
        attempt(
            lambda text: self.pick_rejected.emit(f"nothing picked: {text}"),
            self.model.pick_image_point,
            (u, v),
            refine=self.subpixel.isChecked(),
        )

    # --- a picked point dragged (after Accept too), or clicked to select its pair ------------------------
    def _grab(self, u: float, v: float, radius_px: float) -> bool:
        """Take hold of the complete pair whose point lies within ``radius_px`` of (u, v) on the image
        shown (picked at the robot state it shows). Not while a pair waits for its point: the click is its."""
        if self.model.pairs.pending() is not None:
            return False
        near = [
            (np.hypot(p.pixel[0] - u, p.pixel[1] - v), p.number)
            for p in self.model.pairs
            if p.pixel is not None and (p.view is None or self._same_state(p.view.joints_deg))
        ]
        near = [n for n in near if n[0] <= radius_px]
        self._grabbed = min(near)[1] if near else None
        return self._grabbed is not None

    def _dragging(self, u: float, v: float) -> None:
        self._drag_at = (u, v)
        self.refresh_overlay()

    def _dropped(self, u: float, v: float, moved: bool) -> None:
        number, self._grabbed, self._drag_at = self._grabbed, None, None
        if number is None:
            return
        self.pair_selected.emit(number)
        if moved:
            attempt(
                self.pick_rejected.emit,
                self.model.move_pair_pixel,
                number,
                (u, v),
                refine=self.subpixel.isChecked(),
            )
        self.refresh_overlay()

    def set_board_corners(self, corners_px: np.ndarray | None, text: str = "") -> None:
        """Show a board detection (n, 2) px over the image (``None`` hides it); it belongs to the
        robot state it was detected at and is hidden when the robot moves."""
        self._board_corners = None if corners_px is None else np.asarray(corners_px, dtype=float)
        self._board_joints = None if corners_px is None else np.array(self.model.joints_deg, dtype=float)
        self._board_text = text
        self.refresh_overlay()

    def set_proposals(self, proposals, joints_deg=None) -> None:
        """Show Find points' proposals ``[(u, v, label), ...]`` px over the image (``None`` hides them),
        found on a frame at ``joints_deg``: hidden when the image shows another robot state."""
        self._proposals = None if not proposals else list(proposals)
        self._proposal_joints = None if joints_deg is None else np.asarray(joints_deg, dtype=float)
        self.refresh_overlay()

    def _points_found(self, found) -> None:
        if found is None:
            self.set_proposals(None)
        else:
            self.set_proposals(
                [(p.uv_px[0], p.uv_px[1], p.feature) for p in found.result.proposals], found.view.joints_deg
            )

    def set_edges_image(self, rgba: np.ndarray | None) -> None:
        self._edges_image = rgba
        self.refresh_overlay()

    def _on_solved(self) -> None:
        # The reprojected points and residuals are drawn at once; the CAD edges take a render, so they
        # follow on the next turn of the event loop, after that repaint.
        if self.model.result.estimate is None:
            self._edges_image = None
        else:
            QTimer.singleShot(0, self._draw_solved_edges)
        self.refresh_overlay()

    def _draw_solved_edges(self) -> None:
        r = self.model.result.estimate
        if r is None:
            return
        self.set_edges_image(self.solved_edges.render(self.model.components, r.cam2world_measured, self.model.target))
        self.edges_drawn += 1

    def close_renderer(self) -> None:
        self.solved_edges.close()

    # --- which robot state the image shows ----------------------------------------------------------
    def shown_joints(self) -> np.ndarray:
        """The joints (deg/mm) of the robot state the image shows: the held frame's, else the robot's now."""
        held = self.held
        return np.array(held.stamp.joints_deg) if held is not None else np.asarray(self.model.joints_deg, dtype=float)

    def _same_state(self, joints) -> bool:
        if joints is None:
            return True
        a, b = np.asarray(joints, float), self.shown_joints()
        return a.shape == b.shape and float(np.max(np.abs(a - b))) <= SAME_STATE_DEG

    def _state_key(self) -> tuple:
        model = self.model
        context = model.result.context
        pairs = tuple(p.view is None or self._same_state(p.view.joints_deg) for p in model.pairs if p.pixel is not None)
        result = context is None or context.joints_deg is None or self._same_state(context.joints_deg)
        board = self._board_joints is None or self._same_state(self._board_joints)
        return pairs, result, board

    def _joints_changed(self, _q) -> None:
        # the robot moved: redraw only when what belongs to the shown state changed
        if self._state_key() != self._drawn_state:
            self.refresh_overlay()

    def refresh_overlay(self) -> None:
        model = self.model
        self._drawn_state = (pairs_current, result_current, board_current) = self._state_key()
        overlay = Overlay()
        banner = []
        pending = model.pairs.pending()
        picked = [p for p in model.pairs if p.pixel is not None]
        for pair, current in zip(picked, pairs_current):
            color = (PICK_COLOR if pair.enabled else QColor(130, 130, 130)) if current else STALE_COLOR
            u, v = self._drag_at if pair.number == self._grabbed and self._drag_at is not None else pair.pixel
            overlay.points.append((u, v, str(pair.number) if current else f"{pair.number}?", color))
        if not all(pairs_current):
            banner.append(
                f"picks {', '.join(str(p.number) for p, c in zip(picked, pairs_current) if not c)} were made at "
                "another robot pose (grey)"
            )
        result = model.result.estimate
        stale = model.stale_reason
        if result is not None and not result_current:
            banner.append("the last result was solved at another robot pose: not drawn")
        elif result is not None:
            self._draw_result(overlay, model, result)
            if stale:
                banner.append(f"the result is from an earlier set of pairs ({stale})")
        if pending is not None:
            overlay.text = f"pick point {pending.number} ({pending.feature or 'surface point'}) on the camera image"
            expected = self.model.expected_pixel()
            if expected is not None:
                (u, v), basis = expected
                overlay.points.append((u, v, "expected", EXPECTED_COLOR))
                overlay.text += f"; it should lie near the white mark ({basis})"
        if self._proposals:
            if self._same_state(self._proposal_joints):
                for u, v, label in self._proposals:
                    overlay.points.append((u, v, label, PROPOSAL_COLOR))
                overlay.text = "blue: points found (Find points); accept them in the list"
            else:
                banner.append("the points found were found at another robot pose: not drawn")
        if self._board_corners is not None:
            if board_current:
                for u, v in self._board_corners:
                    overlay.points.append((u, v, "", BOARD_COLOR))
                overlay.text = self._board_text
            else:
                banner.append("the board detection was made at another robot pose: not drawn")
        overlay.banner = "; ".join(banner)
        self.view.set_overlay(overlay)

    def _draw_result(self, overlay: Overlay, model: CameraPaneModel, result) -> None:
        obj2cam = concat(result.obj2world, invert(result.cam2world_measured))
        used = set(model.result.solved_numbers)
        for pair in model.pairs:
            if pair.pixel is None or pair.number not in used:
                continue
            p_obj = apply(invert(result.obj2world), np.array(pair.point_world_mm)[None])
            uv = project_points(p_obj, obj2cam, self.model.intrinsics)[0]
            if np.all(np.isfinite(uv)):
                overlay.points.append((uv[0], uv[1], "", REPROJECTED_COLOR))
                end = np.array(pair.pixel) + RESIDUAL_SCALE * (np.array(pair.pixel) - uv)
                overlay.segments.append((uv[0], uv[1], end[0], end[1], RESIDUAL_COLOR))
        overlay.text = f"cyan: model points from the solved pose; red: residuals x{RESIDUAL_SCALE:g}"
        candidates = result.solution.candidates
        if len(candidates) > 1:
            # Ghosts of the other poses that fit as well, so the operator can tell them apart.
            for k, candidate in enumerate(candidates):
                if k == model.result.chosen_candidate:
                    continue
                for pair in model.pairs:
                    p_obj = apply(invert(result.obj2world), np.array(pair.point_world_mm)[None])
                    uv = project_points(p_obj, candidate.obj2cam, self.model.intrinsics)[0]
                    if np.all(np.isfinite(uv)):
                        overlay.points.append((uv[0], uv[1], f"s{k + 1}", GHOST_COLOR))
            overlay.text = f"{len(candidates)} poses fit: magenta ghosts show the others; choose one in Results"
        if self.edges.isChecked() and self._edges_image is not None:
            overlay.image = self._edges_image
            overlay.image_opacity = self.opacity.value() / 100.0
