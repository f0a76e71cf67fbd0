"""The solver bench's scenes and peers, shared by its sections (bench/solver_bench.py, bench/solver_speed.py): the
camera, random poses with their points and pixels, a pose displaced from the truth, OpenCV's solvers, a timer."""

from __future__ import annotations

import time

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform

CAM = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960)
K = CAM.K
NOISE_PX = 0.5


def _scene(rng: np.random.Generator, n: int, planar: bool = False):
    """A random pose (object ~500 mm away, all points inside the image) and its points (n, 3) mm."""
    while True:
        R = Rotation.from_rotvec(rng.normal(0, 0.35, 3)).as_matrix()
        t = np.array([rng.uniform(-60, 60), rng.uniform(-50, 50), rng.uniform(400, 600)])
        P = rng.uniform(-75, 75, (n, 3))
        if planar:
            P[:, 2] = 0.0
        T = make_transform(R, t)
        uv = project_points(P, T, CAM)
        if CAM.contains(uv, margin_px=20).all():
            return T, P, uv


def _displaced(rng, truth, dist_mm, angle_deg):
    """``truth`` moved by ``dist_mm`` along a random direction and turned by ``angle_deg`` about a random axis."""
    d = rng.normal(size=3)
    a = rng.normal(size=3)
    R = Rotation.from_rotvec(np.radians(angle_deg) * a / np.linalg.norm(a)).as_matrix() @ truth[:3, :3]
    return make_transform(R, truth[:3, 3] + dist_mm * d / np.linalg.norm(d))


def _cv_pose(rvec, tvec):
    return make_transform(cv2.Rodrigues(np.asarray(rvec, float).reshape(3))[0], np.asarray(tvec, float).reshape(3))


def _opencv(method, P, uv, start=None):
    try:
        if method == "iterative+guess":
            rvec = cv2.Rodrigues(start[:3, :3])[0]
            ok, rvec, tvec = cv2.solvePnP(
                P,
                uv,
                K,
                None,
                rvec,
                start[:3, 3].reshape(3, 1).copy(),
                useExtrinsicGuess=True,
                flags=cv2.SOLVEPNP_ITERATIVE,
            )
        elif method == "sqpnp+lm":
            ok, rvec, tvec = cv2.solvePnP(P, uv, K, None, flags=cv2.SOLVEPNP_SQPNP)
            rvec, tvec = cv2.solvePnPRefineLM(P, uv, K, None, rvec, tvec)
        elif method == "ippe+lm":
            ok, rvec, tvec = cv2.solvePnP(P, uv, K, None, flags=cv2.SOLVEPNP_IPPE)
            rvec, tvec = cv2.solvePnPRefineLM(P, uv, K, None, rvec, tvec)
        elif method == "epnp":
            ok, rvec, tvec = cv2.solvePnP(P, uv, K, None, flags=cv2.SOLVEPNP_EPNP)
        elif method == "iterative":
            ok, rvec, tvec = cv2.solvePnP(P, uv, K, None, flags=cv2.SOLVEPNP_ITERATIVE)
        else:
            raise ValueError(method)
    except cv2.error:
        return None
    return _cv_pose(rvec, tvec) if ok else None


def _time_per_call(fn, reps):
    fn()
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(reps):
            fn()
        best = min(best, (time.perf_counter() - t0) / reps)
    return best


def _errors(T: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    dt = float(np.linalg.norm(T[:3, 3] - truth[:3, 3]))
    return dt, float(np.degrees(Rotation.from_matrix(T[:3, :3] @ truth[:3, :3].T).magnitude()))
