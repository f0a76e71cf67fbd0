"""The virtual camera pane: the CAD workcell from the modelled camera pose (robot model at the
current joints, hand-eye, intrinsics), the target highlighted; a click picks a 3D point."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import QHBoxLayout, QLabel, QVBoxLayout, QWidget

from app.gui.error_boundary import attempt
from app.gui.image_view import ImageView, Overlay
from calib_core.operator.panes.virtual_camera import VirtualPaneModel
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.render import PickResult, RenderOptions, SceneRenderer

from PySide6.QtGui import QColor

FEATURE_COLOR = QColor(90, 190, 255)
RENDER_SCALE = 0.5  # the pane shows a half-size render: plenty to pick features, half the cost


SELECT_RADIUS_PX = 6.0  # a click this close to a pair's mark (pane pixels) selects the pair


class VirtualPane(QWidget):
    """A click on the target object picks a pair's 3D point in the core (``pick_rejected(text)`` when
    it cannot); ``pair_selected(number)`` when the operator clicks a pair's mark while no pair waits for
    its 3D point; while features are named (:meth:`set_feature_component`), ``feature_picked(hit,
    cam2world (4, 4) mm, the pane's focal px)`` instead of a pick."""

    pair_selected = Signal(int)
    pick_rejected = Signal(str)
    feature_picked = Signal(object, object, float)

    def __init__(self, model: VirtualPaneModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.renderer = SceneRenderer()
        self.view = ImageView(placeholder="rendering...")
        self.info = QLabel("")
        self.info.setTextFormat(Qt.TextFormat.PlainText)  # names from the cell file: never markup
        self.info.setStyleSheet("color: #9aa;")
        bar = QHBoxLayout()
        bar.addWidget(QLabel("<b>Virtual camera</b> (CAD model)"))
        bar.addStretch(1)
        bar.addWidget(self.info)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addLayout(bar)
        layout.addWidget(self.view, 1)
        self.intrinsics = model.scene.intrinsics.without_distortion().scaled(RENDER_SCALE)
        self.view.clicked.connect(self._on_click)
        model.pairs_changed.connect(lambda *_: self.refresh())
        model.target_changed.connect(self.refresh)
        model.scene.camera_model_changed.connect(self._camera_model_changed)
        model.scene.scene_changed.connect(self.refresh)
        self._last_joints = None
        self._render_key = None
        self.feature_component: str | None = None  # naming features: picks land on this component, unsnapped
        self.renders = 0

    def _camera_model_changed(self) -> None:
        self.intrinsics = self.model.scene.intrinsics.without_distortion().scaled(RENDER_SCALE)
        self._render_key = None
        self.refresh()

    def _model_cam2world(self) -> np.ndarray:
        """The modelled camera (4, 4) mm in the base frame at the arm's joints."""
        return self.model.scene.model_cam2world(self.model.joints_deg)

    def refresh(self) -> None:
        """Re-render when the joints or the target changed; otherwise only redraw the overlays."""
        key = (tuple(np.round(self.model.joints_deg, 6)), self.model.target, self.model.scene.version)
        if key != self._render_key:
            self.renderer.set_items(self.model.scene.items(self.model.joints_deg))
            # Feature dots and picks are drawn as 2D overlays, not in 3D: they stay crisp, and they do not
            # cover the very surface points the picker tests for visibility.
            image = self.renderer.render_view(
                self.intrinsics, self._model_cam2world(), RenderOptions(highlight=self.model.target)
            )
            self.view.set_image(image)
            self._render_key = key
            self.renders += 1
        overlay = Overlay()
        world2cam = invert(self._model_cam2world())
        shown = self.feature_component or self.model.target
        if shown is not None:
            target = self.model.scene.component(shown)
            if target.features:
                pts = apply(world2cam, apply(target.item2world, np.array(list(target.features.values()))))
                for uv in project(pts, self.intrinsics, distort=False):
                    if np.all(np.isfinite(uv)):
                        overlay.points.append((uv[0], uv[1], "", FEATURE_COLOR))
        for p in self.model.pairs:
            uv = project(apply(world2cam, np.array(p.point_world_mm)[None]), self.intrinsics, distort=False)[0]
            if np.all(np.isfinite(uv)):
                overlay.points.append((uv[0], uv[1], str(p.number), _qcolor(p.complete)))
        overlay.text = f"target: {self.model.target or '(choose one)'}" + (
            "" if self.model.pairs.pending() else " - click a feature to pick its 3D point"
        )
        self.view.set_overlay(overlay)
        self._last_joints = self.model.joints_deg.copy()

    def is_current(self, tolerance_deg: float = 1e-3) -> bool:
        """Whether the view shows the robot at the current joints (to ``tolerance_deg``)."""
        return (
            self._last_joints is not None
            and float(np.max(np.abs(self.model.joints_deg - self._last_joints))) <= tolerance_deg
        )

    def refresh_if_moved(self, tolerance_deg: float = 1e-3) -> None:
        if not self.is_current(tolerance_deg):
            self.refresh()

    def _pair_at(self, u: float, v: float) -> int | None:
        """The pair whose 3D point is drawn within :data:`SELECT_RADIUS_PX` of (u, v), nearest first."""
        world2cam = invert(self._model_cam2world())
        near = []
        for p in self.model.pairs:
            uv = project(apply(world2cam, np.array(p.point_world_mm)[None]), self.intrinsics, distort=False)[0]
            if np.all(np.isfinite(uv)):
                near.append((float(np.hypot(uv[0] - u, uv[1] - v)), p.number))
        near = [n for n in near if n[0] <= SELECT_RADIUS_PX]
        return min(near)[1] if near else None

    def _on_click(self, u: float, v: float) -> None:
        # A click on a pair's mark selects it, as in the camera pane; while a pair waits for its image
        # point a click here picks its 3D point again, and naming features only picks.
        if self.feature_component is None and self.model.pairs.pending() is None:
            number = self._pair_at(u, v)
            if number is not None:
                self.info.setText(f"pair {number} selected")
                self.pair_selected.emit(number)
                return
        target = self.feature_component or self.model.target
        snap = 0.0 if self.feature_component else 10.0  # naming a feature: the core snaps it to the mesh
        hit: PickResult | None = self.renderer.pick(
            u, v, snap_radius_px=snap, components=None if target is None else {target}
        )
        if hit is None:
            self.info.setText(f"nothing of {target or 'the target object'} there")
            return
        where = (
            f"{hit.component}: {hit.feature or 'surface'} ({', '.join(f'{x:.1f}' for x in hit.point_component_mm)}) mm"
        )
        if self.feature_component is not None:
            self.info.setText(where)
            self.feature_picked.emit(hit, self._model_cam2world(), self.intrinsics.fu)  # the pane's own pixels
            return
        attempt(self.pick_rejected.emit, self._pick, hit, where)

    def _pick(self, hit: PickResult, where: str) -> None:
        number = self.model.pick_model_point(hit.component, hit.feature, hit.point_world_mm)
        self.info.setText(f"pair {number}: {where}")

    def set_feature_component(self, component: str | None) -> None:
        """Name features by clicking on ``component`` (``None``: clicks pick pairs again)."""
        self.feature_component = component
        self.refresh()

    def close_renderer(self) -> None:
        self.renderer.close()


def _qcolor(complete: bool):
    from PySide6.QtGui import QColor

    return QColor(255, 214, 10) if complete else QColor(255, 80, 60)
