"""How a pose measured by PnP moves when what it was measured through changes: the pixels (a shift
shared by every point) or the camera's intrinsics. Central differences of OpenCV's PnP refinement
from the pose itself; first order is enough for corrections of tenths of a pixel."""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole, project_points
from calib_core.frames import make_transform


def pose_derivatives(
    obj2cam: np.ndarray,
    points_mm: np.ndarray,
    intrinsics: Intrinsics,
    changes: list[Callable[[float, np.ndarray], tuple[np.ndarray, Intrinsics]]],
    difference: Callable[[np.ndarray, np.ndarray], np.ndarray],
    step: float,
) -> np.ndarray:
    """(k, len(changes)): the derivative of ``difference(obj2cam, moved)`` (k,) per unit of each change.
    ``points_mm`` (m, 3) in the object's frame, seen at ``obj2cam`` (4, 4) mm through ``intrinsics``;
    each change maps ``(signed step, pixels (m, 2))`` to the pixels and intrinsics to solve with."""
    pts = np.asarray(points_mm, dtype=np.float64).reshape(-1, 3)
    rvec0 = cv2.Rodrigues(obj2cam[:3, :3])[0]
    tvec0 = obj2cam[:3, 3].reshape(3, 1).astype(np.float64)
    pixels = project_points(pts, obj2cam, intrinsics)
    columns = []
    for change in changes:
        moved = []
        for sign in (1.0, -1.0):
            uv, camera = change(sign * step, pixels.copy())
            uv, camera = as_pinhole(uv, camera)  # OpenCV's PnP knows no fisheye lens
            _, rvec, tvec = cv2.solvePnP(
                pts,
                uv,
                camera.K,
                camera.dist_coeffs,
                rvec0.copy(),
                tvec0.copy(),
                useExtrinsicGuess=True,
                flags=cv2.SOLVEPNP_ITERATIVE,
            )
            moved.append(difference(obj2cam, make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel())))
        columns.append((moved[0] - moved[1]) / (2.0 * step))
    return np.column_stack(columns)
