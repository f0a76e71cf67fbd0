"""A VTK camera that is exactly a calibrated pinhole camera.

VTK's own camera has one view angle and a centred principal point; a calibrated camera has
fu != fv and an off-centre principal point. The projection is therefore given explicitly:
an OpenGL projection matrix built from the intrinsics, with OpenCV's pixel convention (the
centre of the top-left pixel is (0, 0)), so a point lands on the pixel ``project()`` gives.
"""

from __future__ import annotations

import numpy as np
from calib_core.render import vtk_api as vtk

from calib_core.camera.intrinsics import Intrinsics

NEAR_MM = 20.0
FAR_MM = 30000.0


def projection_matrix(intrinsics: Intrinsics, near_mm: float = NEAR_MM, far_mm: float = FAR_MM) -> np.ndarray:
    """OpenGL projection (4, 4) from eye coordinates (x right, y up, looking down -z, mm).

    ``x_ndc = 2 (u + 0.5) / w - 1`` and ``y_ndc = 1 - 2 (v + 0.5) / h`` for the pixel
    ``(u, v) = (fu X/Z + cx, fv Y/Z + cy)`` of the OpenCV camera frame.
    """
    w, h = intrinsics.width, intrinsics.height
    n, f = near_mm, far_mm
    P = np.zeros((4, 4))
    P[0, 0] = 2.0 * intrinsics.fu / w
    P[0, 2] = (w - 2.0 * intrinsics.cx - 1.0) / w
    P[1, 1] = 2.0 * intrinsics.fv / h
    P[1, 2] = (2.0 * intrinsics.cy + 1.0 - h) / h
    P[2, 2] = -(f + n) / (f - n)
    P[2, 3] = -2.0 * f * n / (f - n)
    P[3, 2] = -1.0
    return P


def depth_from_zbuffer(zbuffer: np.ndarray, near_mm: float = NEAR_MM, far_mm: float = FAR_MM) -> np.ndarray:
    """Camera-frame depth Z (mm) of OpenGL depth-buffer values in [0, 1]; inf where nothing was drawn."""
    A = -(far_mm + near_mm) / (far_mm - near_mm)
    B = -2.0 * far_mm * near_mm / (far_mm - near_mm)
    z_ndc = 2.0 * np.asarray(zbuffer, dtype=float) - 1.0
    with np.errstate(divide="ignore"):
        Z = B / (A + z_ndc)
    return np.where(zbuffer >= 1.0, np.inf, Z)


def set_vtk_camera(camera: vtk.vtkCamera, intrinsics: Intrinsics, cam2world: np.ndarray) -> None:
    """Make ``camera`` the calibrated camera at pose ``cam2world`` (4, 4, mm, OpenCV axes)."""
    R = np.asarray(cam2world, dtype=float)[:3, :3]
    centre = np.asarray(cam2world, dtype=float)[:3, 3]
    camera.SetPosition(*centre)
    camera.SetFocalPoint(*(centre + 1000.0 * R[:, 2]))
    camera.SetViewUp(*(-R[:, 1]))
    m = vtk.vtkMatrix4x4()
    P = projection_matrix(intrinsics)
    for i in range(4):
        for j in range(4):
            m.SetElement(i, j, P[i, j])
    camera.SetExplicitProjectionTransformMatrix(m)
    camera.SetUseExplicitProjectionTransformMatrix(True)
    camera.SetClippingRange(NEAR_MM, FAR_MM)
