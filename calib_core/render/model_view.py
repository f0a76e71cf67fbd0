"""The cell as the modelled camera sees it, lens distortion included: what Find points and the edge
refinement compare a camera frame with (which edges the model shows, where its faces differ)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from calib_core.camera.distortion_map import distortion_map
from calib_core.camera.intrinsics import Intrinsics
from calib_core.render.renderer import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem


class ModelView:
    """Renders ``items`` (the workcell and the modelled robot) through ``intrinsics``. Offscreen, one
    renderer kept for the object's life; :meth:`close` frees it."""

    def __init__(self, intrinsics: Intrinsics):
        self.intrinsics = intrinsics
        self._map = distortion_map(intrinsics)
        self._renderer: SceneRenderer | None = None
        self._items: list[SceneItem] | None = None

    def render(self, items: list[SceneItem], cam2world: np.ndarray) -> np.ndarray:
        """The image (h, w, 3) uint8 the modelled camera at ``cam2world`` (4, 4, mm) would take."""
        if self._renderer is None:
            self._renderer = SceneRenderer(self._map.ideal.width, self._map.ideal.height)
        if items is not self._items:
            self._renderer.set_items(items)
            self._items = items
        return self._map.apply(self._renderer.render_view(self._map.ideal, cam2world, RenderOptions(show_edges=False)))

    def of(self, items: list[SceneItem], item2world: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """``expected(obj2cam) -> image`` for an object at ``item2world``: the view with the object at
        ``obj2cam`` from the camera (the camera placed accordingly)."""
        return lambda obj2cam: self.render(items, item2world @ np.linalg.inv(obj2cam))

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
