"""A validated pose problem: matched 3D and 2D points, intrinsics and options.

Validation happens once here, so the numerical code can trust its input.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import as_pinhole

from calib_core.solver.kernels.geometry_checks import (
    COLLINEAR,
    NON_FINITE_2D,
    NON_FINITE_3D,
    OUT_OF_RANGE,
    check_pairs,
    close_pairs,
    close_pairs_swept,
)
from calib_core.solver.errors import (
    DegenerateGeometryError,
    DuplicatePointsError,
    RepeatedPairError,
    InvalidIntrinsicsError,
    MismatchedPointsError,
    NonFiniteInputError,
    OutOfRangeInputError,
    PointsBehindCameraError,
    TooFewPointsError,
    point_label,
    points_label,
)

MODELS = ("pinhole", "paper")

# Relative spread along the second principal axis of the 3D points below which they count as collinear.
_COLLINEAR_RATIO = 1e-6
# Relative spread along the third principal axis below which the points count as coplanar (IPPE applies).
COPLANAR_RATIO = 1e-6
# Two 3D points closer than this fraction of the point spread, or two pixels closer than this, are duplicates.
_DUPLICATE_REL_3D = 1e-9
_DUPLICATE_PX = 1e-6


MAX_COORDINATE_MM = 1e7
"""The largest 3D coordinate a solve takes, mm (10 km: a cell is metres; 1e308 overflowed the kernels)."""
MAX_PIXEL = 1e6
"""The largest pixel coordinate a solve takes (a million pixels off any sensor)."""


@dataclass(frozen=True)
class PoseProblem:
    """Point pairs ready for the solver.

    ``points_3d``: (n, 3), mm, object frame. ``points_2d``: (n, 2), px, as observed
    (with lens distortion). ``intrinsics``: the camera. ``coplanar``: whether the 3D
    points lie in one plane.
    """

    points_3d: np.ndarray
    points_2d: np.ndarray
    intrinsics: Intrinsics
    estimate_focal: bool
    model: str
    coplanar: bool
    distortion: np.ndarray
    off_image: tuple[int, ...] = ()
    repeated_3d: tuple[tuple[int, int], ...] = ()
    """Pairs of indices (i < j) naming the same 3D point (seen at two pixels: allowed)."""

    @property
    def n_points(self) -> int:
        return len(self.points_3d)

    @property
    def n_params(self) -> int:
        """Unknowns: 6 for the pose, 8 with the two focal lengths."""
        return 8 if self.estimate_focal else 6


def _as_points(values: ArrayLike, dim: int, name: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as exc:
        raise MismatchedPointsError(f"{name}: not a list of numbers ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise MismatchedPointsError(
            f"{name}: expected a list of [{'x, y, z' if dim == 3 else 'u, v'}] rows, got shape {arr.shape}"
        )
    return np.ascontiguousarray(arr)


def check_intrinsics(intrinsics: Intrinsics) -> None:
    """Raise :class:`InvalidIntrinsicsError` unless both focal lengths are positive and finite."""
    for name, v in (("fu", intrinsics.fu), ("fv", intrinsics.fv)):
        if not (math.isfinite(v) and v > 0):
            raise InvalidIntrinsicsError(f"intrinsics: {name} must be a positive focal length in px, got {v}")


def make_problem(
    points_3d: ArrayLike,
    points_2d: ArrayLike,
    intrinsics: Intrinsics,
    *,
    estimate_focal: bool = False,
    model: str = "pinhole",
) -> PoseProblem:
    """Validate the input of a solve; raise a :class:`SolverInputError` subclass naming the points at fault."""
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
    check_intrinsics(intrinsics)
    p3 = _as_points(points_3d, 3, "points_3d")
    p2 = _as_points(points_2d, 2, "points_2d")
    if len(p3) != len(p2):
        raise MismatchedPointsError(f"{len(p3)} 3D points but {len(p2)} 2D points: every pair needs both")
    needed = 4 if estimate_focal else 3
    if len(p3) < needed:
        why = " (the focal lengths are estimated too)" if estimate_focal else ""
        raise TooFewPointsError(f"{len(p3)} point pairs given, at least {needed} needed{why}")
    code, i, j, coplanar, n_off_image, spread = check_pairs(
        p3, p2, _COLLINEAR_RATIO, COPLANAR_RATIO, intrinsics.width, intrinsics.height, MAX_COORDINATE_MM, MAX_PIXEL
    )
    if code == OUT_OF_RANGE:
        with np.errstate(invalid="ignore"):  # (NaN and infinity are named below)
            absurd = np.flatnonzero(
                (np.isfinite(p3) & (np.abs(p3) > MAX_COORDINATE_MM)).any(axis=1)
                | (np.isfinite(p2) & (np.abs(p2) > MAX_PIXEL)).any(axis=1)
            )
        raise OutOfRangeInputError(
            f"{points_label(absurd)}: a coordinate beyond {MAX_COORDINATE_MM:g} mm or {MAX_PIXEL:g} px (is the unit "
            "right?)",
            absurd,
        )
    if code == NON_FINITE_3D or code == NON_FINITE_2D:
        bad = np.flatnonzero(~np.all(np.isfinite(p3), axis=1) | ~np.all(np.isfinite(p2), axis=1))
        raise NonFiniteInputError(f"{points_label(bad)}: coordinates are NaN or infinite", bad)
    repeated = _repeated_points(p3, p2, _DUPLICATE_REL_3D * max(spread, 1.0))
    if len(p3) - len({j for _, j in repeated}) < needed:
        raise TooFewPointsError(
            f"{len(p3)} point pairs given but only {len(p3) - len({j for _, j in repeated})} distinct 3D points, at "
            f"least {needed} needed"
        )
    if code == COLLINEAR:
        raise DegenerateGeometryError(
            f"{points_label(range(len(p3)))}: the 3D points are collinear; pick points that span a plane or a volume",
            range(len(p3)),
        )
    off_image = ()
    if n_off_image:
        u, v = p2[:, 0], p2[:, 1]
        off_image = tuple(
            int(k)
            for k in np.flatnonzero(
                (u < -0.5) | (v < -0.5) | (u > intrinsics.width - 0.5) | (v > intrinsics.height - 0.5)
            )
        )
    # The kernels know OpenCV's 5-parameter lens; a rational or fisheye lens is solved on the ideal pinhole's pixels,
    # which see the same rays (the pose is the same; residuals are in the ideal image's pixels).
    p2, intrinsics = as_pinhole(p2, intrinsics)
    return PoseProblem(
        p3,
        np.ascontiguousarray(p2),
        intrinsics,
        bool(estimate_focal),
        model,
        bool(coplanar),
        intrinsics.dist_coeffs,
        off_image,
        repeated,
    )


def _repeated_points(p3: np.ndarray, p2: np.ndarray, tol3_mm: float) -> tuple[tuple[int, int], ...]:
    """The pairs naming one 3D point twice (allowed: a feature seen at two pixels); raises
    :class:`DuplicatePointsError` for two pairs at one pixel, or one pair given twice. O(n log n)."""
    same_px = _close_pairs(p2, _DUPLICATE_PX)
    if same_px:
        i, j = same_px[0]
        same = [(a, b) for a, b in same_px if np.linalg.norm(p3[a] - p3[b]) <= tol3_mm]
        kept = set(same)
        other = [(a, b) for a, b in same_px if (a, b) not in kept]
        if other:
            a, b = other[0]
            raise DuplicatePointsError(f"{point_label(a)} and {point_label(b)} have the same pixel", (a, b))
        raise RepeatedPairError(
            f"{point_label(i)} and {point_label(j)} are the same pair (the same 3D point at the same pixel)",
            sorted({k for pair in same for k in pair}),
            same_px,
        )
    return tuple(_close_pairs(p3, tol3_mm))


def first_of_each_pair(
    points_3d: np.ndarray, points_2d: np.ndarray, same_pixel: Sequence[tuple[int, int]] | None = None
) -> np.ndarray:
    """For each pair (n,) the index of the first pair that is the same (the same 3D point at the same
    pixel, to the tolerances the checks use): itself when it is the first. ``same_pixel``: the index pairs (i < j)
    at one pixel, sorted, when a check found them already (:class:`RepeatedPairError`)."""
    p3 = np.asarray(points_3d, dtype=float)
    p2 = np.asarray(points_2d, dtype=float)
    spread = float(np.ptp(p3, axis=0).max()) if len(p3) else 0.0
    first = np.arange(len(p3))
    for i, j in _close_pairs(p2, _DUPLICATE_PX) if same_pixel is None else same_pixel:
        if np.linalg.norm(p3[i] - p3[j]) <= _DUPLICATE_REL_3D * max(spread, 1.0):
            first[j] = min(first[j], first[i])
    return first


def _close_pairs(points: np.ndarray, tol: float) -> list[tuple[int, int]]:
    """Index pairs (i < j) of points within ``tol`` of each other, sorted: a compiled sweep along one direction beyond
    64 points (O(n log n)), a compiled comparison of all pairs below."""
    found = close_pairs(points, tol) if len(points) <= 64 else close_pairs_swept(points, tol)
    return sorted((int(i), int(j)) for i, j in found) if len(found) else []


def check_in_front(points_3d: np.ndarray, obj2cam: np.ndarray, what: str) -> None:
    """Raise :class:`PointsBehindCameraError` if ``obj2cam`` puts any point at z <= 0 (camera frame)."""
    z = points_3d @ obj2cam[2, :3] + obj2cam[2, 3]
    behind = np.flatnonzero(z <= 0)
    if len(behind):
        raise PointsBehindCameraError(
            f"the {what} puts {points_label(behind)} at or behind the camera (z <= 0)", behind
        )
