"""The target's CAD edges and the image's, for matching them: the mesh's crease edges (dihedral angle
over 30 deg) and open boundary, samples along those a camera sees (a face beside them faces it), the
distance transform of the image's Canny edges, and the share of samples that lie on an image edge.

This module once also slid the projected edges over the image as a 2D shift (chamfer
matching) to find the target; close to it a robot's error is no shift (parallax), and
:mod:`calib_core.look.pose_hypotheses` searches camera poses instead.
"""

from __future__ import annotations

import weakref

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

SHARP_DEG = 30.0
TRUNCATE_PX = 8.0
_SAMPLE_STEP_PX = 3.0


_CREASES: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def crease_segments(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    """The mesh's crease and boundary edges: segments (E, 2, 3) mm and the normals of the faces beside
    each (E, 2, 3) (a boundary edge repeats its one face). Kept for the mesh's life: a fit asks for them at every
    resampling, and finding a 20k-face mesh's boundary edges takes 40 ms. (A mesh is not changed in place here.)"""
    key = id(mesh)
    if key not in _CREASES:
        _CREASES[key] = _crease_segments(mesh)
        weakref.finalize(mesh, _CREASES.pop, key, None)
    return _CREASES[key]


def _crease_segments(mesh: trimesh.Trimesh) -> tuple[np.ndarray, np.ndarray]:
    sharp = mesh.face_adjacency_angles > np.radians(SHARP_DEG)
    seg = mesh.vertices[mesh.face_adjacency_edges[sharp]]
    normals = mesh.face_normals[mesh.face_adjacency[sharp]]
    # boundary edges: edges used by one face only (trimesh groups the rows by hashing: a sort of the rows took 0.2 s
    # for a 45k-face mesh)
    lonely = trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1)
    if len(lonely):
        faces = mesh.edges_face[lonely]
        seg = np.concatenate([seg, mesh.vertices[mesh.edges_sorted[lonely]]])
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
    z = seg @ obj2cam[2, :3] + obj2cam[2, 3]
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


def edge_distance_map(image: np.ndarray, truncate_px: float = TRUNCATE_PX) -> np.ndarray:
    """Distance (px, float32, truncated at ``truncate_px``) from every pixel to the nearest image edge (Canny;
    ``image`` grey, or RGB for edges of colour as well: :mod:`calib_core.look.colour_contrast`)."""
    from calib_core.look.image_evidence import ImageEvidence

    return ImageEvidence.of(image).edge_distance(truncate_px)


def matched_share(samples_px: np.ndarray, distance: np.ndarray, within_px: float = 2.0) -> float:
    """The share of edge samples (m, 2) px within ``within_px`` of an image edge (``distance`` (h, w))."""
    if len(samples_px) == 0:
        return 0.0
    h, w = distance.shape
    u = np.rint(samples_px[:, 0]).astype(np.int64)
    v = np.rint(samples_px[:, 1]).astype(np.int64)
    inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
    return float(np.mean(inside & (distance[np.clip(v, 0, h - 1), np.clip(u, 0, w - 1)] <= within_px)))
