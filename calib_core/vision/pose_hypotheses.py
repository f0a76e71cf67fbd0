"""Where to start the edge refinement: poses around the shifted model pose, ranked by how well the
target's edges lie on the image's (truncated chamfer distance).

The 2D shift of :mod:`calib_core.vision.edge_alignment` is a turn of the camera about its centre. A
robot's error also moves the camera's centre, and close to the target that moves its near and far
edges by different amounts (parallax): at the paper's task location, 177 mm from the fixture, the pin
stands 15 px away from where the shift puts it while the plate's outline fits, and the edge refinement
settles with half its samples on the plate, 2.4 mm from the true pose. So the camera's centre is
searched too: moved across and along the line of sight by up to ``reach_mm``, turned back so the
target's middle stays where the shift put it, and rolled about that line. Each pose is scored by the mean distance of its edge samples from the
image's edges (Canny, truncated at :data:`TRUNCATE_PX`), all poses in one vectorised projection; the
best few, a grid step apart, are where the refinement starts.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project

TRUNCATE_PX = 20.0
"""The distance map's cap: wide enough to rank poses 10-20 px apart, one far edge costs no more than this."""
ROLL_DEG = 2.0
"""The largest roll about the line of sight searched: about three times a typical robot's orientation error."""
_LATERAL_STEPS = 9
_DEPTH_STEPS = 5
_ROLL_STEPS = 5
_MAX_SAMPLES = 400


def moved_cameras(obj2cam: np.ndarray, centre_mm: np.ndarray, shifts_mm: np.ndarray, rolls_deg: np.ndarray) -> np.ndarray:
    """``obj2cam`` (4, 4) with the camera's centre moved by each of ``shifts_mm`` (H, 3) (camera axes),
    turned so the point ``centre_mm`` (3,) (camera frame) stays on its line of sight, then rolled by
    ``rolls_deg`` (H,) about that line: (H, 4, 4)."""
    a = centre_mm / np.linalg.norm(centre_mm)
    b = centre_mm[None] - shifts_mm
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    axis = np.cross(b, a)
    angle = np.arctan2(np.linalg.norm(axis, axis=1), b @ a)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(np.linalg.norm(axis, axis=1, keepdims=True) > 1e-15, axis / np.linalg.norm(axis, axis=1, keepdims=True), 0.0)
    turn = Rotation.from_rotvec(np.radians(rolls_deg)[:, None] * a[None]) * Rotation.from_rotvec(unit * angle[:, None])
    moved = np.tile(np.eye(4), (len(shifts_mm), 1, 1))
    moved[:, :3, :3] = turn.as_matrix()
    moved[:, :3, 3] = -np.einsum("hij,hj->hi", moved[:, :3, :3], shifts_mm)
    return moved @ obj2cam


def _costs(distance: np.ndarray, intrinsics: Intrinsics, samples_mm: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """The mean truncated distance (H,) of the samples (m, 3) seen from each pose (H, 4, 4)."""
    pts = np.einsum("hij,nj->hni", poses[:, :3, :3], samples_mm) + poses[:, None, :3, 3]
    uv = project(pts.reshape(-1, 3), intrinsics).reshape(len(poses), -1, 2)
    h, w = distance.shape
    u = np.rint(np.nan_to_num(uv[..., 0], nan=-1.0)).astype(np.int64)
    v = np.rint(np.nan_to_num(uv[..., 1], nan=-1.0)).astype(np.int64)
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    return np.where(inside, distance[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)], TRUNCATE_PX).mean(axis=1)


def _grid(reach_mm: float, roll_deg: float, steps: tuple[int, int, int]) -> np.ndarray:
    lateral = np.linspace(-reach_mm, reach_mm, steps[0])
    depth = np.linspace(-reach_mm, reach_mm, steps[1])
    rolls = np.linspace(-roll_deg, roll_deg, steps[2])
    return np.array([(x, y, z, r) for x in lateral for y in lateral for z in depth for r in rolls])


def rank_starts(distance: np.ndarray, intrinsics: Intrinsics, samples_mm: np.ndarray, obj2cam: np.ndarray, reach_mm: float, keep: int = 3) -> list[np.ndarray]:
    """The ``keep`` best poses (4, 4) to start an edge refinement from, best first, near ``obj2cam``.

    ``distance`` (h, w): each pixel's distance to the nearest image edge, truncated at
    :data:`TRUNCATE_PX` (:func:`calib_core.vision.edge_alignment.edge_distance_map`);
    ``samples_mm`` (m, 3): points on the target's edges that the camera sees (object frame);
    ``reach_mm``: how far the camera's centre may be from ``obj2cam``'s. A grid over that reach, then
    a grid of half its steps around each of the best; candidates closer than a step to a better one
    are left out. The unmoved pose wins a tie: it is what the shift found.
    """
    if len(samples_mm) < 10:
        return [obj2cam]
    if len(samples_mm) > _MAX_SAMPLES:
        samples_mm = samples_mm[np.random.default_rng(0).choice(len(samples_mm), _MAX_SAMPLES, replace=False)]
    centre = np.median(samples_mm @ obj2cam[:3, :3].T + obj2cam[:3, 3], axis=0)

    def poses_at(grid: np.ndarray) -> np.ndarray:
        return moved_cameras(obj2cam, centre, grid[:, :3], grid[:, 3])

    coarse = _grid(reach_mm, ROLL_DEG, (_LATERAL_STEPS, _DEPTH_STEPS, _ROLL_STEPS))
    cost = _costs(distance, intrinsics, samples_mm, poses_at(coarse))
    cost[np.flatnonzero((np.abs(coarse) < 1e-12).all(axis=1))] -= 1e-6
    steps = np.array([2 * reach_mm / (_LATERAL_STEPS - 1)] * 2 + [2 * reach_mm / (_DEPTH_STEPS - 1), 2 * ROLL_DEG / (_ROLL_STEPS - 1)])
    fine_offsets = _grid(1.0, 1.0, (3, 3, 3)) * 0.5 * steps
    best = coarse[np.argsort(cost, kind="stable")[:keep]]
    grid = np.concatenate([coarse, (best[:, None, :] + fine_offsets[None]).reshape(-1, 4)])
    cost = np.concatenate([cost, _costs(distance, intrinsics, samples_mm, poses_at(grid[len(coarse):]))])
    chosen: list[int] = []
    for i in np.argsort(cost, kind="stable"):
        if all(np.max(np.abs(grid[i] - grid[j]) / steps) >= 0.99 for j in chosen):
            chosen.append(int(i))
        if len(chosen) == keep:
            break
    return list(poses_at(grid[chosen]))
