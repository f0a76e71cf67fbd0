"""Lens distortion applied to an ideal render: where each pixel of the distorted image samples
the ideal one. The ideal render is made larger than the image (same focal lengths, shifted
principal point) so that barrel distortion's corners still find something to sample."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, unproject


@dataclass(frozen=True)
class DistortionMap:
    """``ideal``: the intrinsics to render (no distortion, larger canvas); ``map_x``/``map_y``
    (h, w) float32: for each pixel of the real (distorted) image, its position in the ideal render."""

    ideal: Intrinsics
    map_x: np.ndarray
    map_y: np.ndarray

    def apply(self, ideal_image: np.ndarray) -> np.ndarray:
        """The distorted image (h, w, c) from an ideal render of ``self.ideal``."""
        return cv2.remap(
            ideal_image, self.map_x, self.map_y, interpolation=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )


@lru_cache(maxsize=4)
def distortion_map(intrinsics: Intrinsics) -> DistortionMap:
    """The map for a camera with lens distortion (identity-sized canvas when there is none). Kept for the last four
    cameras (about 10 MB each at 1280 x 960): every pixel is undistorted by iteration, 0.6 s at that size, which the
    first Find points of a session paid while the operator waited. Its arrays are shared: read them, never write."""
    w, h = intrinsics.width, intrinsics.height
    u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
    pixels = np.column_stack([u.ravel(), v.ravel()])
    if not intrinsics.has_distortion:
        return _shared(DistortionMap(intrinsics, u.astype(np.float32), v.astype(np.float32)))
    ideal_px = project(unproject(pixels, intrinsics, undistort=True), intrinsics, distort=False)
    # A wide (fisheye) lens sees rays whose ideal pinhole pixels lie far out (infinitely at 90 deg): the canvas stops
    # one image beyond each edge, and the few pixels of the real image beyond it sample its border.
    reach = np.array([w, h], dtype=float)
    ideal_px = np.clip(np.nan_to_num(ideal_px, nan=0.0, posinf=1e9, neginf=-1e9), -reach, 2 * reach)
    lo = np.floor(ideal_px.min(axis=0)) - 2
    hi = np.ceil(ideal_px.max(axis=0)) + 2
    left, top = max(0.0, -lo[0]), max(0.0, -lo[1])
    width = int(max(hi[0], w - 1) + left + 1)
    height = int(max(hi[1], h - 1) + top + 1)
    ideal = Intrinsics(intrinsics.fu, intrinsics.fv, intrinsics.cx + left, intrinsics.cy + top, width, height)
    map_x = (ideal_px[:, 0] + left).reshape(h, w).astype(np.float32)
    map_y = (ideal_px[:, 1] + top).reshape(h, w).astype(np.float32)
    return _shared(DistortionMap(ideal, map_x, map_y))


def _shared(lens_map: DistortionMap) -> DistortionMap:
    # one map serves every caller with these intrinsics: a write to it would change all their renders
    lens_map.map_x.setflags(write=False)
    lens_map.map_y.setflags(write=False)
    return lens_map
