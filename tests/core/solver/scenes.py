"""Synthetic pose problems shared by the solver tests: known poses, exact or noisy pixels."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform

GRIPPER_CAMERA = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960, (-0.18, 0.07, 0.0006, -0.0004, -0.01))
PINHOLE_CAMERA = GRIPPER_CAMERA.without_distortion()


def random_pose(rng: np.random.Generator, distance_mm: float = 500.0) -> np.ndarray:
    """An ``obj2cam`` (4, 4) looking at the object origin from about ``distance_mm``."""
    R = Rotation.from_rotvec(rng.normal(0.0, 0.35, 3)).as_matrix()
    t = np.array([rng.uniform(-60, 60), rng.uniform(-50, 50), distance_mm * rng.uniform(0.8, 1.2)])
    return make_transform(R, t)


def random_points(rng: np.random.Generator, n: int, size_mm: float = 120.0, planar: bool = False) -> np.ndarray:
    """``n`` object points (n, 3) mm within a cube (or square, z = 0) of side ``size_mm``."""
    P = rng.uniform(-size_mm / 2, size_mm / 2, (n, 3))
    if planar:
        P[:, 2] = 0.0
    return P


def pixels(
    P: np.ndarray,
    obj2cam: np.ndarray,
    intrinsics: Intrinsics = GRIPPER_CAMERA,
    noise_px: float = 0.0,
    rng: np.random.Generator | None = None,
) -> np.ndarray:
    """Observed pixels (n, 2) of points ``P`` at pose ``obj2cam``, with Gaussian noise."""
    uv = project_points(P, obj2cam, intrinsics)
    if noise_px:
        uv = uv + (rng or np.random.default_rng(0)).normal(0.0, noise_px, uv.shape)
    return uv


def pose_error(obj2cam: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """(translation error mm, rotation error deg) between two ``obj2cam`` poses."""
    dt = float(np.linalg.norm(obj2cam[:3, 3] - truth[:3, 3]))
    angle = float(np.degrees(Rotation.from_matrix(obj2cam[:3, :3] @ truth[:3, :3].T).magnitude()))
    return dt, angle
