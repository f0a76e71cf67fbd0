"""The workcell overview: the whole cell, the robot following the joints, the modelled camera
frustum and, after a solve, the measured one; orbit (left drag), pan (right or middle drag), zoom (wheel)."""

from __future__ import annotations

import html
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QPointF, Qt, QTimer
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from app.gui.image_view import ImageView
from calib_core.operator.panes.overview import OverviewPaneModel
from calib_core.scene_framing import cell_framing, eye_at
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.render.frustum import frustum_polyline
from calib_core.scene import SceneItem

MODEL_FRUSTUM = (0.35, 0.6, 1.0)
MEASURED_FRUSTUM = (0.2, 1.0, 0.4)


class _OrbitView(ImageView):
    """An image view whose left drag orbits and wheel zooms the camera instead of the image."""

    def __init__(self, pane):
        super().__init__(placeholder="rendering...")
        self.pane = pane
        self._orbit_from: QPointF | None = None
        self._pan_from: QPointF | None = None

    def mousePressEvent(self, event):
        if event.button() == Qt.MouseButton.LeftButton:
            self._orbit_from = event.position()
        elif event.button() in (Qt.MouseButton.RightButton, Qt.MouseButton.MiddleButton):
            self._pan_from = event.position()
        else:
            super().mousePressEvent(event)

    def mouseMoveEvent(self, event):
        if self._orbit_from is not None:
            d = event.position() - self._orbit_from
            self._orbit_from = event.position()
            self.pane.orbit(-0.4 * d.x(), 0.3 * d.y())
        elif self._pan_from is not None:
            d = event.position() - self._pan_from
            self._pan_from = event.position()
            self.pane.pan(d.x(), d.y())
        else:
            super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event):
        self._orbit_from = None
        self._pan_from = None
        super().mouseReleaseEvent(event)

    def wheelEvent(self, event):
        self.pane.dolly(0.85 if event.angleDelta().y() > 0 else 1.18)


class OverviewPane(QWidget):
    def __init__(self, model: OverviewPaneModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.renderer = SceneRenderer()
        self.view = _OrbitView(self)
        self.view.setCursor(Qt.CursorShape.OpenHandCursor)
        bar = QHBoxLayout()
        bar.addWidget(QLabel("<b>Workcell overview</b>"))
        bar.addStretch(1)
        legend = QLabel(
            "<span style='color:#5a9aff'>model camera</span>  <span style='color:#33ff66'>measured camera</span>"
        )
        bar.addWidget(legend)
        self.preview_bar = QWidget()
        self.preview_bar.setObjectName("move_preview")
        pb = QHBoxLayout(self.preview_bar)
        pb.setContentsMargins(4, 2, 4, 2)
        self.preview_text = QLabel("")
        self.preview_text.setWordWrap(True)
        self.move_button = QPushButton("Move")
        self.move_button.setObjectName("confirm_move")
        self.move_button.setToolTip("Send the previewed move to the controller")
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setObjectName("cancel_move")
        pb.addWidget(self.preview_text, 1)
        pb.addWidget(self.move_button)
        pb.addWidget(self.cancel_button)
        self.preview_bar.hide()
        self.move_button.clicked.connect(self._confirm)
        self.cancel_button.clicked.connect(self._cancel)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addLayout(bar)
        layout.addWidget(self.preview_bar)
        layout.addWidget(self.view, 1)
        self.preview = None  # the move shown as a ghost (a MovePreview), or None
        self._send: Callable[[], None] | None = None  # sends the previewed move once confirmed
        self.target = np.zeros(3)
        self.azimuth_deg, self.elevation_deg, self.distance_mm = -130.0, 32.0, 4300.0
        self.fit_view()
        self.redraws = 0
        self._dirty = True
        self._path: list[np.ndarray] = []  # joints still to show in an animation (play_path)
        self._shown_joints: np.ndarray | None = None  # the animation's joints now shown, or None: the robot's
        self._path_timer = QTimer(self)
        self._path_timer.timeout.connect(self._path_step)
        model.result_changed.connect(self.mark_dirty)
        model.target_changed.connect(self.mark_dirty)
        model.scene.scene_changed.connect(self.mark_dirty)
        model.scene.camera_model_changed.connect(self.mark_dirty)
        model.pairs_changed.connect(lambda *_: self.mark_dirty())
        model.move_previewed.connect(lambda preview: self.show_preview(preview))
        model.motion_changed.connect(self._motion_changed)
        model.prompts_withdrawn.connect(self._withdraw_prompt)

    # --- previewed moves ------------------------------------------------------------------------
    def show_preview(self, preview, send: Callable[[], None] | None = None) -> None:
        """Draw ``preview`` (a MovePreview) as a ghost robot at its goal with the tool's path; with
        ``send``, the move waits for *Move* (or *Cancel*). ``None`` clears it."""
        self.preview, self._send = preview, send
        if preview is None:
            self.preview_bar.hide()
        else:
            state = (
                "refused" if preview.blocked else ("waiting for your confirmation" if send is not None else "moving")
            )
            color = "#ff6b6b" if preview.blocked else ("#ffb347" if send is not None else "#9ad0ff")
            self.preview_text.setText(
                f"<span style='color:{color}'><b>{html.escape(state)}</b></span> - "
                f"{html.escape(preview.summary, quote=False)}"
            )
            self.move_button.setVisible(send is not None and not preview.blocked)
            self.cancel_button.setText("Cancel" if send is not None else ("Hide" if preview.blocked else "Stop"))
            self.preview_bar.show()
        self.mark_dirty()

    def _cancel(self) -> None:
        """Cancel a move waiting for Move; while one runs, the button is Stop (``$STP``)."""
        if (
            self._send is None
            and self.preview is not None
            and self.model.robot_state.motion.value == "moving"
            and self.model.robot_state.what == self.preview.what
        ):
            self.model.stop_robot()
            return
        self.show_preview(None)

    def _withdraw_prompt(self) -> None:
        """A Stop (Esc, *Stop*) voids a move still waiting for *Move*."""
        if self._send is not None:
            self.show_preview(None)

    def _confirm(self) -> None:
        send, self._send = self._send, None
        self.move_button.hide()
        if send is not None:
            send()

    def _motion_changed(self, state) -> None:
        # The ghost shows where a move would go until it runs; it goes when the move ended well, and comes
        # back with the reason when it did not.
        self.mark_dirty()
        if self.preview is not None and self._send is None and state.what == self.preview.what:
            if state.motion.value == "arrived":
                self.show_preview(None)
            elif state.motion.value in ("refused", "failed", "unknown"):
                self.cancel_button.setText("Hide")
                self.preview_text.setText(
                    f"<span style='color:#ff6b6b'><b>{html.escape(state.motion.value)}</b></span> - "
                    f"{html.escape(state.text, quote=False)}"
                )

    def _ghost_items(self) -> list:
        p = self.preview
        moving = (
            self._send is None and not p.blocked and self.model.robot_state.motion.value == "moving"
            if p is not None
            else False
        )
        if p is None or moving:
            # While the robot runs the move the real one heads there: the tool's path line is enough, and a
            # second robot would halve the overview's rate with a vendor robot's meshes.
            return []
        color = (1.0, 0.3, 0.3) if p.blocked else ((1.0, 0.7, 0.3) if self._send is not None else (0.45, 0.75, 1.0))
        q = p.path_deg[p.contact_step] if (p.blocked and p.contact_step is not None) else p.goal_deg
        items = []
        for item in self.model.scene.robot_items(q):
            items.append(
                SceneItem(
                    name="ghost/" + item.name,
                    mesh=item.mesh,
                    item2world=item.item2world,
                    color=color,
                    kind="ghost",
                    opacity=0.35,
                )
            )
        return items

    def orbit(self, d_azimuth: float, d_elevation: float) -> None:
        self.azimuth_deg += d_azimuth
        self.elevation_deg = float(np.clip(self.elevation_deg + d_elevation, -5.0, 85.0))
        self.mark_dirty()
        self.refresh()

    def pan(self, dx_px: float, dy_px: float) -> None:
        """Slide the view with the mouse (right or middle drag): the point looked at moves in the image plane."""
        a, e = np.radians(self.azimuth_deg), np.radians(self.elevation_deg)
        forward = -np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
        right = np.cross(forward, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        mm_per_px = 2.0 * self.distance_mm * np.tan(np.radians(20.0)) / max(self.view.height(), 1)
        self.target = self.target - right * dx_px * mm_per_px + up * dy_px * mm_per_px
        self.mark_dirty()
        self.refresh()

    def dolly(self, factor: float) -> None:
        self.distance_mm = float(np.clip(self.distance_mm * factor, 800.0, 15000.0))
        self.mark_dirty()
        self.refresh()

    def fit_view(self) -> None:
        """Frame the cell: its components and the robot where it stands (a floor or a wall, far wider
        than it is thick, does not count), seen from the current direction."""
        self.target, self.distance_mm = cell_framing(
            list(self.model.scene.components) + self.model.scene.robot_items(self.model.joints_deg)
        )
        self.mark_dirty()

    def play_path(self, joints_deg: list[np.ndarray], interval_ms: int = 40) -> None:
        """Animate the model robot along joint vectors (deg) in this pane only: the robot does not
        move and the other panes keep the real joints; at the end the pane shows them again."""
        self._path = list(joints_deg)
        self._path_timer.setInterval(interval_ms)
        self._path_timer.start()

    def _path_step(self) -> None:
        self._shown_joints = self._path.pop(0) if self._path else None
        if self._shown_joints is None:
            self._path_timer.stop()
        self.mark_dirty()
        self.refresh()

    def mark_dirty(self) -> None:
        self._dirty = True

    def eye(self) -> np.ndarray:
        return eye_at(self.target, self.distance_mm, self.azimuth_deg, self.elevation_deg)

    def refresh(self) -> None:
        """Redraw only when something changed (joints, a solve, the view)."""
        if not self._dirty:
            return
        # extra_items: things put up in the cell for a while (the calibration board), shown where they stand.
        q = self.model.joints_deg if self._shown_joints is None else self._shown_joints
        self.renderer.set_items(self.model.scene.items(q) + self._ghost_items())
        lines = [
            (
                frustum_polyline(
                    self.model.scene.intrinsics, self.model.scene.model_cam2world(self.model.joints_deg), 300.0
                ),
                MODEL_FRUSTUM,
            )
        ]
        if self.preview is not None and self.preview.tcp_path_mm is not None and len(self.preview.tcp_path_mm) > 1:
            lines.append((self.preview.tcp_path_mm, (1.0, 0.7, 0.3)))
        if self.model.estimate is not None:
            lines.append(
                (
                    frustum_polyline(self.model.scene.intrinsics, self.model.estimate.cam2world_measured, 300.0),
                    MEASURED_FRUSTUM,
                )
            )
        markers = [(np.array(p.point_world_mm), (1.0, 0.84, 0.04)) for p in self.model.pairs]
        size = self.view.size()
        w, h = max(size.width(), 320), max(size.height(), 240)
        image = self.renderer.render_overview(
            self.eye(),
            self.target,
            width=w,
            height=h,
            options=RenderOptions(highlight=self.model.target, lines=lines, markers=markers, feature_size_px=8),
        )
        self.view.set_image(image)
        self.redraws += 1
        self._dirty = False
