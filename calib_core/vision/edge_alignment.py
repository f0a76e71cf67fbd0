"""Where the target is in the image, to the pixel: its CAD crease edges, projected at the modelled pose,
slid over the image's edges (chamfer matching on a distance transform). The robot's error moves the
whole target by tens of pixels, mostly as a shift; this finds the shift, so each feature's detector
searches a few pixels instead of a hundred.

Edges are the mesh's sharp edges (dihedral angle over 30 deg) and its open boundary, kept when a face
beside them faces the camera. Other objects in front of the target are not modelled: their edges cost
a little, the truncated distance keeps them from dominating.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

SHARP_DEG = 30.0
TRUNCATE_PX = 8.0
_SAMPLE_STEP_PX = 3.0


@dataclass(frozen=True)
class EdgeAlignment:
    """``offset_px`` (2,): how far the image's target lies from the modelled one; ``mean_distance_px``
    the matched samples' mean distance to an image edge (truncated at 8 px: 8 means no match);
    ``samples`` how many edge samples were matched; ``distinct`` the best cost over the best one at
    least 6 px away (below 1: a clear minimum); ``matched_share`` the share of samples within 2 px of an
    image edge at the offset (edges of low contrast, or hidden by other objects, are not matched)."""

    offset_px: np.ndarray
    mean_distance_px: float
    samples: int
    distinct: float
    matched_share: float = 0.0
    alternatives: tuple = ()
    """The next best shifts (2,) px, each at least 8 px from the better ones: where to start again when
    the best one leads nowhere (a parallel edge taken for the target's)."""


def crease_segments(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """The mesh's crease and boundary edges: segments (E, 2, 3) mm and the normals of the faces beside
    each (E, 2, 3) (a boundary edge repeats its one face)."""
    sharp = mesh.face_adjacency_angles > np.radians(SHARP_DEG)
    seg = mesh.vertices[mesh.face_adjacency_edges[sharp]]
    normals = mesh.face_normals[mesh.face_adjacency[sharp]]
    # boundary edges: edges used by one face only
    edges = np.sort(mesh.edges, axis=1)
    unique, index, counts = np.unique(edges, axis=0, return_index=True, return_counts=True)
    lonely = counts == 1
    if lonely.any():
        faces = mesh.edges_face[index[lonely]]
        seg = np.concatenate([seg, mesh.vertices[unique[lonely]]])
        normals = np.concatenate([normals, np.repeat(mesh.face_normals[faces][:, None, :], 2, axis=1)])
    return seg, normals


def edge_samples_px(mesh: trimesh.Trimesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Pixels (m, 2) along the crease edges a camera at ``obj2cam`` sees (a face beside them faces it)."""
    seg, normals = crease_segments(mesh)
    if len(seg) == 0:
        return np.zeros((0, 2))
    centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]  # the camera centre in the object frame
    mid = seg.mean(axis=1)
    facing = np.einsum("eij,ej->ei", normals, centre - mid) > 0
    seg = seg[facing.any(axis=1)]
    z = (seg @ obj2cam[2, :3] + obj2cam[2, 3])
    seg = seg[(z > 1.0).all(axis=1)]
    if len(seg) == 0:
        return np.zeros((0, 2))
    ends = project_points(seg.reshape(-1, 3), obj2cam, intrinsics).reshape(-1, 2, 2)
    lengths = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    counts = np.clip(np.ceil(lengths / _SAMPLE_STEP_PX).astype(int), 1, 2000)
    s = np.concatenate([(np.arange(c) + 0.5) / c for c in counts])
    which = np.repeat(np.arange(len(seg)), counts)
    points_3d = seg[which, 0] + (seg[which, 1] - seg[which, 0]) * s[:, None]
    uv = project_points(points_3d, obj2cam, intrinsics)
    return uv[intrinsics.contains(uv, margin_px=2)]


def edge_distance_map(grey: np.ndarray, truncate_px: float = TRUNCATE_PX) -> np.ndarray:
    """Distance (px, float32, truncated at ``truncate_px``) from every pixel to the nearest image edge (Canny)."""
    edges = cv2.Canny(cv2.GaussianBlur(grey, (5, 5), 1.0), 20, 60)
    dist = cv2.distanceTransform((edges == 0).astype(np.uint8), cv2.DIST_L2, 3)
    return np.minimum(dist, truncate_px).astype(np.float32)


def _distances(samples: np.ndarray, distance: np.ndarray, offset: np.ndarray) -> np.ndarray:
    h, w = distance.shape
    u = np.rint(samples[:, 0] + offset[0]).astype(np.int64)
    v = np.rint(samples[:, 1] + offset[1]).astype(np.int64)
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    return np.where(inside, distance[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)], TRUNCATE_PX)


def matched_share(samples_px: np.ndarray, distance: np.ndarray, within_px: float = 2.0) -> float:
    """The share of edge samples (m, 2) px within ``within_px`` of an image edge (``distance`` (h, w))."""
    if len(samples_px) == 0:
        return 0.0
    return float(np.mean(_distances(samples_px, distance, np.zeros(2)) <= within_px))


def _costs(samples: np.ndarray, distance: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    h, w = distance.shape
    u = np.rint(samples[None, :, 0] + offsets[:, None, 0]).astype(np.int64)
    v = np.rint(samples[None, :, 1] + offsets[:, None, 1]).astype(np.int64)
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    d = np.where(inside, distance[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)], TRUNCATE_PX)
    return d.mean(axis=1)


def align_edges(samples_px: np.ndarray, distance: np.ndarray, radius_px: float) -> EdgeAlignment:
    """The shift (within ``radius_px``) that lays the edge samples on the image's edges: coarse on a
    4 px grid, then every pixel around the best, then a parabola through the best's neighbours."""
    if len(samples_px) < 10:
        return EdgeAlignment(np.zeros(2), TRUNCATE_PX, len(samples_px), 1.0, 0.0)
    rng = np.random.default_rng(0)
    coarse_samples = samples_px if len(samples_px) <= 800 else samples_px[rng.choice(len(samples_px), 800, replace=False)]
    r = int(np.ceil(radius_px / 4.0)) * 4
    grid = np.arange(-r, r + 1, 4, dtype=float)
    offsets = np.stack(np.meshgrid(grid, grid, indexing="xy"), axis=-1).reshape(-1, 2)
    offsets = offsets[np.linalg.norm(offsets, axis=1) <= radius_px + 4]
    costs = np.concatenate([_costs(coarse_samples, distance, chunk) for chunk in np.array_split(offsets, max(1, len(offsets) // 256))])
    best = offsets[int(np.argmin(costs))]
    far = np.linalg.norm(offsets - best, axis=1) >= 6
    fine_grid = np.arange(-4, 5, dtype=float)
    fine = best + np.stack(np.meshgrid(fine_grid, fine_grid, indexing="xy"), axis=-1).reshape(-1, 2)
    fine_costs = _costs(samples_px, distance, fine)
    k = int(np.argmin(fine_costs))
    offset = fine[k].copy()
    table = fine_costs.reshape(9, 9)
    row, col = divmod(k, 9)
    for axis, (i, j) in ((0, (row, col)), (1, (row, col))):
        idx = j if axis == 0 else i
        if 0 < idx < 8:
            left = table[i, j - 1] if axis == 0 else table[i - 1, j]
            right = table[i, j + 1] if axis == 0 else table[i + 1, j]
            denom = left - 2 * table[i, j] + right
            if denom > 1e-9:
                offset[axis] += 0.5 * (left - right) / denom
    second = float(costs[far].min()) if far.any() else TRUNCATE_PX
    best_cost = float(fine_costs[k])
    matched = matched_share(samples_px + fine[k], distance)
    alternatives = []
    taken = [best]
    for i in np.argsort(costs):
        if len(alternatives) == 3:
            break
        candidate = offsets[i]
        if all(np.linalg.norm(candidate - t) >= 8.0 for t in taken):
            taken.append(candidate)
            alternatives.append(candidate.astype(float))
    return EdgeAlignment(offset, best_cost, len(samples_px), best_cost / max(second, 1e-9), matched, tuple(alternatives))
