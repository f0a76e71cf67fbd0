"""What a part's deviation from its CAD does to a look: the pose's covariance when every feature of the part lies
off its CAD position by a random amount (1-sigma ``tolerance_mm`` along each axis, independently a feature).

The residuals cannot show it: a smooth form error moves the features in ways the pose mostly absorbs (on the
simulated workshop cell a millimetre of form error left 0.3-0.5 px of RMS and turned the measured camera by
0.5 deg). First order: the pose moves by ``-(J^T J)^-1 J^T A dX`` for feature offsets ``dX``, where ``J`` (2m, 6)
is the image points' derivative by the pose and ``A`` (2m, 3m) by the features' positions.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

_STEP_MM = 0.01
_STEP_RAD = 1e-5


def _pose_jacobian(obj2cam: np.ndarray, points: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """(2m, 6) derivative of the pixels by the solver's parameters (dt mm, phi rad, camera frame), central differences
    through the lens."""
    columns = []
    for k in range(6):
        moved = []
        for sign in (1.0, -1.0):
            T = obj2cam.copy()
            if k < 3:
                T[k, 3] += sign * _STEP_MM
            else:
                T[:3, :3] = Rotation.from_rotvec(sign * _STEP_RAD * np.eye(3)[k - 3]).as_matrix() @ obj2cam[:3, :3]
            moved.append(project_points(points, T, intrinsics).ravel())
        columns.append((moved[0] - moved[1]) / (2.0 * (_STEP_MM if k < 3 else _STEP_RAD)))
    return np.column_stack(columns)


def form_error_covariance(
    obj2cam: np.ndarray, points_obj_mm: np.ndarray, intrinsics: Intrinsics, tolerance_mm: float
) -> np.ndarray:
    """(6, 6) covariance, in the solver's (dt mm, phi rad) on ``obj2cam`` (4, 4) mm, from the features
    ``points_obj_mm`` (m, 3, the object's frame) lying off their CAD positions by ``tolerance_mm`` (1-sigma per axis,
    independent). Zeros without a tolerance or with fewer than 4 points."""
    pts = np.asarray(points_obj_mm, dtype=float).reshape(-1, 3)
    if tolerance_mm <= 0 or len(pts) < 4:
        return np.zeros((6, 6))
    J = _pose_jacobian(np.asarray(obj2cam, float), pts, intrinsics)
    # A feature moved by dX in the object's frame moves its pixel as the camera-frame translation does, turned by R:
    # with an isotropic dX, A A^T per point is the translation columns' own product.
    Jt = J[:, :3].reshape(-1, 2, 3)
    AAt = np.zeros((2 * len(pts), 2 * len(pts)))
    for i, block in enumerate(Jt):
        AAt[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = block @ block.T
    H_inv = np.linalg.pinv(J.T @ J)
    return tolerance_mm**2 * H_inv @ J.T @ AAt @ J @ H_inv
