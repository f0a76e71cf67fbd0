"""A part's stated form tolerance in the image: how far its real edges may lie from its CAD's, in pixels, which an edge
fit to the CAD cannot settle closer than."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.scene import SceneItem


def form_error_px(item: SceneItem, obj2cam: np.ndarray, intrinsics: Intrinsics) -> float:
    """How far, px, a part made to its stated form tolerance (:attr:`SceneItem.form_tolerance_mm`, 1-sigma an axis) may
    lie from its CAD in the image at ``obj2cam`` (4, 4, mm): the tolerance at the depth of the mesh's centre; 0 for a
    part made as drawn. (Raising the settle bound to it was tried: on the workshop camera at full size, parts 0.5 mm
    off their CAD at 180 mm and 1120 px focal, the fits then settled on wrong poses and the corrections were 4.3-4.7 mm
    off, outside their 3-sigma. Find points looks at the image halved instead, :mod:`~calib_core.look.halved_look`,
    and says why a look there is refused.)"""
    if item.form_tolerance_mm <= 0.0:
        return 0.0
    centre = np.asarray(item.mesh.vertices, dtype=float).mean(axis=0)
    depth = float(centre @ obj2cam[2, :3] + obj2cam[2, 3])
    return item.form_tolerance_mm * max(intrinsics.fu, intrinsics.fv) / depth if depth > 0.0 else 0.0
