"""Many independent pose problems solved at once, vectorised over the batch.

Same camera model, update and Jacobian as a single solve (the model code broadcasts).
Without starting poses, each problem is seeded by a batched direct linear transform
(six or more non-coplanar points) or, failing that, by OpenCV's SQPnP one by one. Meant
for Monte-Carlo studies, benchmarks and re-solving recordings; it does not search for
ambiguous alternatives (use :func:`solve_pose` for an operator's solve).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole
from calib_core.solver.errors import MismatchedPointsError, NonFiniteInputError, TooFewPointsError
from calib_core.solver.initialisation import normalized_coordinates, sqpnp_seed
from calib_core.solver.kernels.dlt import dlt_pose_batch
from calib_core.solver.kernels.camera_models import PINHOLE
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT, newton_batch
from calib_core.solver.problem import check_intrinsics
from calib_core.solver.uncertainty import DEFAULT_SIGMA_PX


@dataclass(frozen=True)
class BatchPoseSolution:
    """Per-problem results, each with the batch size ``b`` first.

    ``obj2cam`` (b, 4, 4) mm; ``fu``, ``fv`` (b,) px; ``rms_px`` (b,); ``iterations`` (b,);
    ``converged`` (b,) bool; ``std_t_obj2cam_mm`` (b, 3); ``std_rotation_deg`` (b, 3) about
    the camera axes; ``std_camera_position_mm`` (b, 3) in the object frame; ``sigma_px`` (b,)
    the noise the covariance was scaled with (estimated when there is redundancy).
    """

    obj2cam: np.ndarray
    fu: np.ndarray
    fv: np.ndarray
    rms_px: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray
    std_t_obj2cam_mm: np.ndarray
    std_rotation_deg: np.ndarray
    std_camera_position_mm: np.ndarray
    sigma_px: np.ndarray

    def __len__(self) -> int:
        return len(self.obj2cam)


def _dlt_seeds(P: np.ndarray, uv: np.ndarray, intrinsics: Intrinsics) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Batched DLT: rotations (b, 3, 3), translations (b, 3) mm, and which seeds are usable (b,)."""
    b = len(P)
    R = np.zeros((b, 3, 3))
    t = np.zeros((b, 3))
    ok = np.zeros(b, dtype=np.bool_)
    dlt_pose_batch(P, normalized_coordinates(uv, intrinsics, intrinsics.fu, intrinsics.fv), R, t, ok)
    return R, t, ok


def _check_batch(points_3d, points_2d, estimate_focal) -> tuple[np.ndarray, np.ndarray]:
    P = np.asarray(points_3d, dtype=float)
    uv = np.asarray(points_2d, dtype=float)
    if P.ndim != 3 or P.shape[2] != 3 or uv.shape != P.shape[:2] + (2,):
        raise MismatchedPointsError(
            f"batch: expected points_3d (b, n, 3) and points_2d (b, n, 2), got {P.shape} and {uv.shape}"
        )
    needed = 4 if estimate_focal else 3
    if P.shape[1] < needed:
        raise TooFewPointsError(f"batch: {P.shape[1]} point pairs per problem, at least {needed} needed")
    bad = np.flatnonzero(~(np.isfinite(P).all(axis=(1, 2)) & np.isfinite(uv).all(axis=(1, 2))))
    if len(bad):
        raise NonFiniteInputError(
            f"batch: problems {', '.join(map(str, bad[:10]))} contain NaN or infinite coordinates"
        )
    return P, uv


def solve_pose_batch(
    points_3d: ArrayLike,
    points_2d: ArrayLike,
    intrinsics: Intrinsics,
    *,
    starts: ArrayLike | None = None,
    estimate_focal: bool = False,
    sigma_px: float | None = None,
    max_iterations: int = 100,
) -> BatchPoseSolution:
    """Solve ``b`` independent problems: ``points_3d`` (b, n, 3) mm, ``points_2d`` (b, n, 2) px.

    ``starts`` (b, 4, 4): starting ``obj2cam`` poses; without them each problem is seeded
    as described in the module docstring. All problems share ``intrinsics``.
    """
    check_intrinsics(intrinsics)
    P, uv = _check_batch(points_3d, points_2d, estimate_focal)
    b, n, _ = P.shape
    if (
        intrinsics.model != "plumb_bob"
    ):  # the kernel knows OpenCV's 5-parameter lens: the ideal pinhole sees the same rays
        flat, intrinsics = as_pinhole(uv.reshape(-1, 2), intrinsics)
        uv = np.ascontiguousarray(flat.reshape(b, n, 2))
    if starts is not None:
        S = np.asarray(starts, dtype=float)
        if S.shape != (b, 4, 4):
            raise MismatchedPointsError(f"batch: starts must be ({b}, 4, 4), got {S.shape}")
        R, t = S[:, :3, :3].copy(), S[:, :3, 3].copy()
    else:
        R, t, usable = (
            _dlt_seeds(np.ascontiguousarray(P), uv, intrinsics)
            if n >= 6
            else (np.zeros((b, 3, 3)), np.zeros((b, 3)), np.zeros(b, bool))
        )
        for i in np.flatnonzero(~usable):
            seed = sqpnp_seed(P[i], uv[i], intrinsics, intrinsics.fu, intrinsics.fv)
            if seed:
                R[i], t[i] = seed[0]
    f = np.tile([intrinsics.fu, intrinsics.fv], (b, 1))
    R, t = np.ascontiguousarray(R), np.ascontiguousarray(t)
    r = np.empty((b, n, 2))
    J = np.empty((b, n, 2, 8 if estimate_focal else 6))
    iterations = np.zeros(b, dtype=np.int64)
    outcomes = np.zeros(b, dtype=np.int64)
    newton_batch(
        PINHOLE,
        np.ascontiguousarray(P),
        np.ascontiguousarray(uv),
        R,
        t,
        f,
        intrinsics.cx,
        intrinsics.cy,
        intrinsics.dist_coeffs,
        estimate_focal,
        max_iterations,
        r,
        J,
        iterations,
        outcomes,
    )
    converged = (outcomes == CONVERGED) | (outcomes == EXACT_FIT)
    return _summarise(R, t, f[:, 0], f[:, 1], r, J, iterations, converged, sigma_px)


def _summarise(R, t, fu, fv, r, J, iterations, converged, sigma_px) -> BatchPoseSolution:
    b, n, _ = r.shape
    p = J.shape[-1]
    obj2cam = np.zeros((b, 4, 4))
    obj2cam[:, :3, :3], obj2cam[:, :3, 3], obj2cam[:, 3, 3] = R, t, 1.0
    cost = np.einsum("bnk,bnk->b", r, r)
    redundancy = 2 * n - p
    if sigma_px is not None:
        sigma = np.full(b, float(sigma_px))
    elif redundancy > 0:
        sigma = np.sqrt(cost / redundancy)
    else:
        sigma = np.full(b, DEFAULT_SIGMA_PX)
    Jf = J.reshape(b, -1, p)
    info = np.swapaxes(Jf, 1, 2) @ Jf
    with np.errstate(all="ignore"):
        cov = np.linalg.pinv(info, hermitian=True) * (sigma**2)[:, None, None]
    var = np.einsum("bii->bi", cov)
    Rt = np.swapaxes(R, 1, 2)
    tx, ty, tz = t[:, 0], t[:, 1], t[:, 2]
    zero = np.zeros(b)
    t_cross = np.stack([np.stack([zero, -tz, ty], 1), np.stack([tz, zero, -tx], 1), np.stack([-ty, tx, zero], 1)], 1)
    A = np.concatenate([-Rt, -Rt @ t_cross], axis=2)
    cov_c = A @ cov[:, :6, :6] @ np.swapaxes(A, 1, 2)
    return BatchPoseSolution(
        obj2cam=obj2cam,
        fu=fu,
        fv=fv,
        rms_px=np.sqrt(cost / n),
        iterations=iterations,
        converged=converged,
        std_t_obj2cam_mm=np.sqrt(var[:, :3]),
        std_rotation_deg=np.degrees(np.sqrt(var[:, 3:6])),
        std_camera_position_mm=np.sqrt(np.einsum("bii->bi", cov_c)),
        sigma_px=sigma,
    )
