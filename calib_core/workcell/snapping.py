"""Where a click on a mesh should land when it defines a feature: the centre of a circle (a round
boss, a hole, a pin's end) the click is on, a sharp corner near it, a vertex near it, or the
surface point itself. Points are in the mesh's own frame, mm.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import trimesh

_CORNER_ANGLE_DEG = 30.0
_CIRCLE_MIN_POINTS = 8
_CIRCLE_ROUNDNESS = 0.02  # radius spread / radius
_CIRCLES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # mesh -> its circles, found once


@dataclass(frozen=True)
class Snap:
    """``point_mm`` (3,) in the mesh frame; ``kind``: ``circle_centre``, ``corner``, ``vertex`` or
    ``surface``; ``distance_mm`` from the clicked point."""

    point_mm: np.ndarray
    kind: str
    distance_mm: float


def _circle_centres(mesh: trimesh.Trimesh) -> list[tuple[np.ndarray, float]]:
    """(centre (3,), radius mm) of every flat facet whose outline is a circle."""
    cached = _CIRCLES.get(mesh)
    if cached is not None:
        return cached
    circles = []
    for boundary in mesh.facets_boundary:
        points = mesh.vertices[np.unique(boundary)]
        if len(points) < _CIRCLE_MIN_POINTS:
            continue
        centre = points.mean(axis=0)
        radii = np.linalg.norm(points - centre, axis=1)
        if radii.mean() > 0 and radii.std() < _CIRCLE_ROUNDNESS * radii.mean():
            circles.append((centre, float(radii.mean())))
    _CIRCLES[mesh] = circles
    return circles


def _is_corner(mesh: trimesh.Trimesh, vertex: int) -> bool:
    normals = mesh.face_normals[[f for f in mesh.vertex_faces[vertex] if f >= 0]]
    distinct: list[np.ndarray] = []
    cos_limit = np.cos(np.radians(_CORNER_ANGLE_DEG))
    for n in normals:
        if all(float(n @ d) < cos_limit for d in distinct):
            distinct.append(n)
    return len(distinct) >= 3


def snap_point(mesh: trimesh.Trimesh, point_mm, radius_mm: float) -> Snap:
    """Snap a clicked surface point ``point_mm`` (3,) of ``mesh`` within ``radius_mm``."""
    point = np.asarray(point_mm, dtype=float).reshape(3)
    for centre, radius in _circle_centres(mesh):
        if np.linalg.norm(point - centre) <= max(radius, radius_mm) and _on_plane_of(mesh, point, centre):
            return Snap(centre.copy(), "circle_centre", float(np.linalg.norm(point - centre)))
    d = np.linalg.norm(mesh.vertices - point, axis=1)
    near = np.flatnonzero(d <= radius_mm)
    near = near[np.argsort(d[near])]
    for v in near:
        if _is_corner(mesh, int(v)):
            return Snap(mesh.vertices[v].copy(), "corner", float(d[v]))
    if len(near):
        return Snap(mesh.vertices[near[0]].copy(), "vertex", float(d[near[0]]))
    return Snap(point, "surface", 0.0)


def _on_plane_of(mesh: trimesh.Trimesh, point: np.ndarray, centre: np.ndarray, tol_mm: float = 0.5) -> bool:
    # The click must be on the circle's own flat face, not on a face behind or beside it.
    for facet, boundary in zip(mesh.facets, mesh.facets_boundary):
        pts = mesh.vertices[np.unique(boundary)]
        if np.linalg.norm(pts.mean(axis=0) - centre) < 1e-6:
            normal = mesh.face_normals[facet[0]]
            return abs(float((point - centre) @ normal)) <= tol_mm
    return False
