"""The CAD edges seen from the measured camera pose, through the lens, as an overlay of the video.

Rendered at half size (a quarter of the cost) and enlarged, in a renderer of its own: the virtual
camera's renderer must keep its last frame for picking.
"""

from __future__ import annotations

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem
from calib_core.camera.distortion_map import distortion_map


class SolvedEdges:
    """``render`` gives an RGBA image (h, w, 4) of the camera image's size; transparent where no edge is."""

    def __init__(self, intrinsics: Intrinsics):
        self._renderer: SceneRenderer | None = None  # made on the first solve: start-up does not pay for it
        self.set_intrinsics(intrinsics)

    def set_intrinsics(self, intrinsics: Intrinsics) -> None:
        self.intrinsics = intrinsics
        self._half = None  # the lens's map, made on the first solve too (0.1 s of start-up otherwise)

    def render(self, items: list[SceneItem], cam2world: np.ndarray, highlight: str | None) -> np.ndarray:
        """The edges of ``items`` seen from ``cam2world`` (4, 4) mm, the camera that took the image."""
        if self._renderer is None:
            self._renderer = SceneRenderer()
        if self._half is None:
            self._half = distortion_map(self.intrinsics.scaled(0.5))
        self._renderer.set_items(items)
        rgba = self._renderer.render_view(
            self._half.ideal, cam2world, RenderOptions(style="edges", transparent_background=True, highlight=highlight)
        )
        return cv2.resize(
            self._half.apply(rgba), (self.intrinsics.width, self.intrinsics.height), interpolation=cv2.INTER_LINEAR
        )

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
