"""Starting poses without a guess: a DLT for many points, every root of P3P, SQPnP, IPPE
for planar points.

OpenCV supplies the closed-form seeds except the DLT (compiled here, because it is cheap);
each is refined afterwards by the Newton solver. Seeds are object-to-camera poses
``(R (3, 3), t (3,) mm)``.
"""

from __future__ import annotations


import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import undistort_normalized
from calib_core.solver.kernels.dlt import dlt_pose
from calib_core.solver.kernels.fast_path import largest_triangles
from calib_core.solver.problem import PoseProblem

# P3P over subsets is run for small problems (where other local minima are likely and must be
# reported) and as a fallback when the all-points seeds fit badly (a mis-click spoils SQPnP).
SMALL_PROBLEM_POINTS = 5
P3P_SEEDED_UP_TO = 8
"""Up to this many pairs on a plane, P3P over the largest triangles seeds the search too: SQPnP and IPPE's
two poses can miss a minimum that fits a plane's six to eight pairs about as well as the best."""
MAX_SUBSETS = 6


def _camera(intrinsics: Intrinsics, fu: float, fv: float) -> tuple[np.ndarray, np.ndarray]:
    K = np.array([[fu, 0.0, intrinsics.cx], [0.0, fv, intrinsics.cy], [0.0, 0.0, 1.0]])
    return K, intrinsics.dist_coeffs


def _as_seeds(rvecs, tvecs) -> list[tuple[np.ndarray, np.ndarray]]:
    if len(rvecs) == 0:
        return []
    rv = np.asarray(rvecs, dtype=float).reshape(-1, 3)
    tv = np.asarray(tvecs, dtype=float).reshape(-1, 3)
    finite = np.isfinite(rv).all(axis=1) & np.isfinite(tv).all(axis=1)
    return [(cv2.Rodrigues(rv[k])[0], tv[k].copy()) for k in np.flatnonzero(finite)]


def normalized_coordinates(points_2d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float) -> np.ndarray:
    """Undistorted normalized image coordinates (..., 2) of pixels (..., 2)."""
    xy = np.empty(points_2d.shape)
    xy[..., 0] = (points_2d[..., 0] - intrinsics.cx) / fu
    xy[..., 1] = (points_2d[..., 1] - intrinsics.cy) / fv
    if intrinsics.has_distortion:
        xy = undistort_normalized(xy.reshape(-1, 2), intrinsics.distortion, intrinsics.model).reshape(points_2d.shape)
    return xy


def dlt_seed(problem: PoseProblem, fu: float, fv: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The DLT pose for six or more non-coplanar pairs (empty list when it does not apply)."""
    if problem.n_points < 6 or problem.coplanar:
        return []
    R = np.empty((3, 3))
    t = np.empty(3)
    if dlt_pose(problem.points_3d, normalized_coordinates(problem.points_2d, problem.intrinsics, fu, fv), R, t):
        return [(R, t)]
    return []


def p3p_seeds(
    points_3d: np.ndarray, points_2d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every real root of P3P on exactly three pairs (up to four poses)."""
    K, dist = _camera(intrinsics, fu, fv)
    try:
        n, rvecs, tvecs = cv2.solveP3P(
            points_3d.reshape(3, 1, 3), points_2d.reshape(3, 1, 2), K, dist, flags=cv2.SOLVEPNP_P3P
        )
    except cv2.error:
        return []
    return _as_seeds(rvecs[:n], tvecs[:n]) if n else []


def sqpnp_seed(
    points_3d: np.ndarray, points_2d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The global minimum of SQPnP's algebraic cost (one pose), for four or more pairs."""
    K, dist = _camera(intrinsics, fu, fv)
    try:
        ok, rvec, tvec = cv2.solvePnP(points_3d, points_2d, K, dist, flags=cv2.SOLVEPNP_SQPNP)
    except cv2.error:
        return []
    return _as_seeds([rvec], [tvec]) if ok else []


def ippe_seeds(
    points_3d: np.ndarray, points_2d: np.ndarray, intrinsics: Intrinsics, fu: float, fv: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Both poses IPPE finds for four or more coplanar pairs (the planar two-fold ambiguity)."""
    K, dist = _camera(intrinsics, fu, fv)
    try:
        n, rvecs, tvecs, _ = cv2.solvePnPGeneric(points_3d, points_2d, K, dist, flags=cv2.SOLVEPNP_IPPE)
    except cv2.error:
        return []
    return _as_seeds(rvecs[:n], tvecs[:n]) if n else []


_ENUMERATE_UP_TO = 12  # C(12, 3) = 220 triplets: below this, every one is looked at
_SAMPLED_TRIPLETS = 200


def spread_triplets(points_3d: np.ndarray, limit: int = MAX_SUBSETS) -> list[tuple[int, int, int]]:
    """Up to ``limit`` triplets of point indices, the largest triangles first (best conditioned P3P).

    Up to 12 points every triplet is ranked; beyond, a bounded set is: the triangle on the points
    farthest apart, and 200 random triplets (seeded, so the same picks give the same seeds). Time
    and memory O(n), never the n^3 / 6 of all combinations."""
    P = np.asarray(points_3d, dtype=float)
    n = len(P)
    if n < 3:
        return []
    if n <= _ENUMERATE_UP_TO:
        # (the fast path's own ranking, so that both paths seed from the same triangles)
        return [tuple(int(v) for v in tri) for tri in largest_triangles(np.ascontiguousarray(P), limit)]
    rng = np.random.default_rng(n)
    drawn = np.sort(np.stack([rng.choice(n, 3, replace=False) for _ in range(_SAMPLED_TRIPLETS)]), axis=1)
    i = int(np.argmax(np.linalg.norm(P - P.mean(axis=0), axis=1)))
    j = int(np.argmax(np.linalg.norm(P - P[i], axis=1)))
    d = P[j] - P[i]
    off_line = np.linalg.norm(np.cross(P - P[i], d), axis=1)
    k = int(np.argmax(off_line))
    triplets = (
        np.unique(np.vstack([drawn, np.sort([i, j, k])[None]]), axis=0)
        if len({i, j, k}) == 3
        else np.unique(drawn, axis=0)
    )
    area = np.linalg.norm(
        np.cross(P[triplets[:, 1]] - P[triplets[:, 0]], P[triplets[:, 2]] - P[triplets[:, 0]]), axis=1
    )
    order = np.argsort(-area, kind="stable")[:limit]
    return [tuple(int(v) for v in triplets[o]) for o in order]


def subset_p3p_seeds(problem: PoseProblem, fu: float, fv: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """P3P roots over several triplets of the pairs."""
    seeds = []
    for tri in spread_triplets(problem.points_3d):
        idx = list(tri)
        seeds += p3p_seeds(problem.points_3d[idx], problem.points_2d[idx], problem.intrinsics, fu, fv)
    return seeds


def initial_seeds(
    problem: PoseProblem, fu: float, fv: float, gate_px: float | None = None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Seeds for a problem without a guess: P3P roots for 3 pairs; DLT (6 or more pairs off a
    plane), SQPnP, IPPE when planar, P3P over triplets when there are few pairs (up to eight on a
    plane). With ``gate_px`` (known focal lengths only) the triplets' roots that put all the pairs
    more than that off (RMS) are left out, unless none is within it."""
    P, uv, intr = problem.points_3d, problem.points_2d, problem.intrinsics
    if problem.n_points == 3:
        return p3p_seeds(P, uv, intr, fu, fv)
    seeds = dlt_seed(problem, fu, fv) + sqpnp_seed(P, uv, intr, fu, fv)
    if problem.coplanar:
        seeds += ippe_seeds(P, uv, intr, fu, fv)
    # A plane's 6-8 pairs: the triplets too where the fast path seeds from them (a gate: known focal lengths, pinhole,
    # not robust), so that both paths find the same minima; a robust solve's consensus is judged as before.
    plane_triplets = problem.coplanar and problem.n_points <= P3P_SEEDED_UP_TO and gate_px is not None
    if problem.n_points <= SMALL_PROBLEM_POINTS or plane_triplets:
        roots = subset_p3p_seeds(problem, fu, fv)
        if gate_px is not None and roots:
            # Each triplet's roots: the true pose and up to three others that the remaining pairs
            # refute by tens to hundreds of pixels. Every minimum that fits all the pairs has a root
            # of each triplet near it, so the refuted ones would only be refined to be dropped.
            rms = seed_rms_px(problem, roots, fu, fv)
            near = rms <= gate_px
            roots = [r for r, keep in zip(roots, near) if keep] if near.any() else roots
        seeds += roots
    return seeds


def seed_rms_px(problem: PoseProblem, seeds: list[tuple[np.ndarray, np.ndarray]], fu: float, fv: float) -> np.ndarray:
    """RMS reprojection error (k,) px of each seed over all the pairs, pinhole in undistorted
    coordinates (a gate, not a fit); inf where a point is behind the camera."""
    R = np.stack([r for r, _ in seeds])
    t = np.stack([t for _, t in seeds])
    X = np.einsum("kij,nj->kni", R, problem.points_3d) + t[:, None, :]
    z = X[..., 2]
    xy = normalized_coordinates(problem.points_2d, problem.intrinsics, fu, fv)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = X[..., :2] / z[..., None] - xy[None]
    e2 = (d[..., 0] * fu) ** 2 + (d[..., 1] * fv) ** 2
    rms = np.sqrt(np.mean(e2, axis=1))
    return np.where((z > 0).all(axis=1) & np.isfinite(rms), rms, np.inf)


def distinct_seeds(
    seeds: list[tuple[np.ndarray, np.ndarray]], angle_deg: float = 2.0, rel_translation: float = 0.02
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The seeds with near-copies left out (within ``angle_deg`` and ``rel_translation`` of the distance
    of one kept before): P3P over overlapping triplets gives the same pose several times, and each copy
    would be refined to the same minimum. Order kept."""
    if len(seeds) < 2:
        return list(seeds)
    R = np.stack([r for r, _ in seeds])
    t = np.stack([v for _, v in seeds])
    cos_limit = np.cos(np.radians(angle_deg))
    # all pairs at once: same turn (cos of the relative angle from the trace) and same place
    cos = (np.einsum("aij,bij->ab", R, R) - 1.0) / 2.0
    scale = np.maximum(np.linalg.norm(t, axis=1), 1.0)
    near = (cos >= cos_limit) & (np.linalg.norm(t[:, None] - t[None], axis=2) <= rel_translation * scale[:, None])
    kept: list[int] = []
    for i in range(len(seeds)):
        if not near[i, kept].any():
            kept.append(i)
    return [seeds[i] for i in kept]
