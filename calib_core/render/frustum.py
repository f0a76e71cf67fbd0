"""A camera frustum as a polyline in the world frame, for the overview."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import unproject
from calib_core.frames import apply


def frustum_polyline(intrinsics: Intrinsics, cam2world: np.ndarray, depth_mm: float = 250.0) -> np.ndarray:
    """Points (k, 3) mm tracing the pyramid from the camera centre to the image corners at ``depth_mm``."""
    w, h = intrinsics.width, intrinsics.height
    corners = unproject(
        np.array([[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]]),
        intrinsics,
        undistort=False,
        depth_mm=depth_mm,
    )
    c = np.zeros(3)
    a, b, d, e = corners  # top left, top right, bottom right, bottom left
    path = np.array([a, b, d, e, a, c, b, d, c, e])  # every edge of the pyramid once (b-d twice)
    return apply(cam2world, path)
