"""Projection and back-projection through the pinhole camera with lens distortion: OpenCV's 5- and 8-parameter
models and its fisheye (equidistant) model.

Pixels follow OpenCV: the centre of the top-left pixel is (0, 0). Points in the camera
frame are in mm, +z along the optical axis, +x to the right of the image, +y down.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import ArrayLike

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import apply

_UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)


def _model_of(distortion: np.ndarray, model: str | None) -> str:
    if model is not None:
        return model
    return {5: "plumb_bob", 8: "rational_polynomial"}.get(len(distortion)) or _no_model(len(distortion))


def _no_model(n: int) -> str:
    raise ValueError(f"{n} distortion coefficients: say the model (plumb_bob 5, rational_polynomial 8, equidistant 4)")


def distort_normalized(xy: ArrayLike, distortion: ArrayLike, model: str | None = None) -> np.ndarray:
    """Apply the lens model to normalized image coordinates (n, 2) -> (n, 2). ``model``: ``plumb_bob`` (5
    coefficients) or ``rational_polynomial`` (8), OpenCV's pinhole models (default: told by the count), or
    ``equidistant`` (4: OpenCV's fisheye model, r -> theta (1 + k1 theta^2 + ... + k4 theta^8) with theta = atan r)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    d = np.asarray(distortion, dtype=float).ravel()
    model = _model_of(d, model)
    x, y = xy[:, 0], xy[:, 1]
    r2 = x * x + y * y
    if model == "equidistant":
        k1, k2, k3, k4 = d
        r = np.sqrt(r2)
        theta = np.arctan(r)
        t2 = theta * theta
        theta_d = theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(r > 1e-12, theta_d / r, 1.0)
        return xy * scale[:, None]
    k1, k2, p1, p2, k3 = d[:5]
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    if model == "rational_polynomial":
        k4, k5, k6 = d[5:8]
        radial = radial / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)))
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
    return np.stack([xd, yd], axis=1)


def undistort_normalized(xy_distorted: ArrayLike, distortion: ArrayLike, model: str | None = None) -> np.ndarray:
    """Invert :func:`distort_normalized` (iteratively, to about 1e-14), (n, 2) -> (n, 2): ``cv2.undistortPointsIter``
    for the pinhole models, ``cv2.fisheye.undistortPoints`` for ``equidistant``."""
    xy = np.asarray(xy_distorted, dtype=float).reshape(-1, 1, 2)
    d = np.asarray(distortion, dtype=float).ravel()
    model = _model_of(d, model)
    if not np.any(d):
        return xy.reshape(-1, 2).copy()
    if model == "equidistant":
        out = cv2.fisheye.undistortPoints(xy, np.eye(3), d.reshape(4, 1), criteria=_UNDISTORT_CRITERIA)
        return out.reshape(-1, 2)
    out = cv2.undistortPointsIter(xy, np.eye(3), d, None, None, _UNDISTORT_CRITERIA)
    return out.reshape(-1, 2)


def project(points_cam_mm: ArrayLike, intrinsics: Intrinsics, *, distort: bool = True) -> np.ndarray:
    """Pixels (n, 2) of points (n, 3) given in the camera frame (mm).

    Points at or behind the camera (z <= 0) give NaN pixels. With ``distort=False``
    the lens distortion is ignored (the ideal pinhole image).
    """
    p = np.asarray(points_cam_mm, dtype=float).reshape(-1, 3)
    z = p[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        xy = p[:, :2] / z[:, None]
    xy[z <= 0] = np.nan
    if distort and intrinsics.has_distortion:
        xy = distort_normalized(xy, intrinsics.distortion, intrinsics.model)
    u = intrinsics.fu * xy[:, 0] + intrinsics.cx
    v = intrinsics.fv * xy[:, 1] + intrinsics.cy
    return np.stack([u, v], axis=1)


def project_points(
    points_obj_mm: ArrayLike, obj2cam: ArrayLike, intrinsics: Intrinsics, *, distort: bool = True
) -> np.ndarray:
    """Pixels (n, 2) of points (n, 3) in an object frame (mm) seen with pose ``obj2cam`` (4x4, mm)."""
    return project(apply(obj2cam, points_obj_mm), intrinsics, distort=distort)


def unproject(
    pixels: ArrayLike, intrinsics: Intrinsics, *, undistort: bool = True, depth_mm: ArrayLike | None = None
) -> np.ndarray:
    """Back-project pixels (n, 2).

    Without ``depth_mm``: unit-free rays (n, 3) with z = 1 in the camera frame.
    With ``depth_mm`` (scalar or (n,)): points (n, 3) in the camera frame at that z, mm.
    ``undistort=False`` treats the pixels as ideal pinhole pixels.
    """
    px = np.asarray(pixels, dtype=float).reshape(-1, 2)
    xy = np.stack([(px[:, 0] - intrinsics.cx) / intrinsics.fu, (px[:, 1] - intrinsics.cy) / intrinsics.fv], axis=1)
    if undistort and intrinsics.has_distortion:
        xy = undistort_normalized(xy, intrinsics.distortion, intrinsics.model)
    rays = np.concatenate([xy, np.ones((len(xy), 1))], axis=1)
    if depth_mm is None:
        return rays
    return rays * np.asarray(depth_mm, dtype=float).reshape(-1, 1)


def undistort_pixels(pixels: ArrayLike, intrinsics: Intrinsics) -> np.ndarray:
    """Ideal pinhole pixels (n, 2) of observed (distorted) pixels (n, 2)."""
    return project(unproject(pixels, intrinsics), intrinsics, distort=False)


def as_pinhole(pixels: ArrayLike, intrinsics: Intrinsics) -> tuple[np.ndarray, Intrinsics]:
    """``(pixels, intrinsics)`` for code that knows OpenCV's 5-parameter model only (the solver's kernels,
    ``cv2.solvePnP`` of a fisheye lens): unchanged for ``plumb_bob``; for another model the ideal pinhole pixels (n, 2)
    and the ideal pinhole camera, which see the same rays."""
    pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
    if intrinsics.model == "plumb_bob":
        return pixels, intrinsics
    return undistort_pixels(pixels, intrinsics), intrinsics.without_distortion()
