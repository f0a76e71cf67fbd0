"""Reading the paper's parameters ``h = (d_x, d_y, d_z, R)`` as a metric pose and back.

The paper's model (see :mod:`calib_core.solver.kernels.camera_models`) has image shifts
``d_x``, ``d_y`` (px) where a pinhole camera has a translation in mm. It equals a rigid
pinhole camera only while the object sits on the optical axis; off axis it fits three
points exactly yet gives a biased pose (see ``docs/solver.md``). Kept to reproduce the paper.
"""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics


def paper_shift_from_pose(t_mm: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float) -> np.ndarray:
    """The paper's ``(d_x px, d_y px, d_z mm)`` that puts the object origin where ``t`` (3,) mm does."""
    return np.array([fu * t_mm[0] / t_mm[2] + intrinsics.cx, fv * t_mm[1] / t_mm[2] + intrinsics.cy, t_mm[2]])


def pose_translation_from_paper_shift(d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float) -> np.ndarray:
    """The object origin in the camera frame (3,) mm read off the paper's ``h``.

    ``t = ((d_x - c_x) d_z / fu, (d_y - c_y) d_z / fv, d_z)``; exact only on axis.
    """
    return np.array([(d[0] - intrinsics.cx) * d[2] / fu, (d[1] - intrinsics.cy) * d[2] / fv, d[2]])


def paper_to_metric_jacobian(d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float, n_params: int) -> np.ndarray:
    """d(t_x, t_y, t_z, phi, [fu, fv]) / d(d_x, d_y, d_z, phi, [fu, fv]), (p, p): carries the
    covariance of ``h`` over to the metric pose."""
    T = np.eye(n_params)
    T[0, 0], T[0, 2] = d[2] / fu, (d[0] - intrinsics.cx) / fu
    T[1, 1], T[1, 2] = d[2] / fv, (d[1] - intrinsics.cy) / fv
    if n_params == 8:
        T[0, 6] = -(d[0] - intrinsics.cx) * d[2] / fu**2
        T[1, 7] = -(d[1] - intrinsics.cy) * d[2] / fv**2
    return T
