"""Whether the target can be in the camera's view at all where the model puts it: in front of the camera and inside
its image (widened by the search's reach), and not hidden behind other parts of the cell in the model's view; which
of its features it shows, not hidden by itself. Find points asked where it cannot be says so and names the way (Go to
task), not "pick the points by hand"."""

from __future__ import annotations

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points


MIN_SHOWN_SAMPLES = 40
"""Fewer of the target's edge samples (3 px apart) in the model's view of the cell than this, and the target is not in
the camera's view to speak of (behind other parts, or outside the image): at the window's first screen, with the
robot at home, the model showed 23 of the fixture's; at its task location 548. Only where the model's view hides most
of them (:func:`hidden_in_view`): a small object far off shows as few and is in sight (LM-O's ape, 96 % in sight,
39)."""


def hidden_in_view(shown: np.ndarray, mesh: trimesh.Trimesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> bool:
    """Whether the model's view hides most of the target: ``shown`` (k, ...) the edge samples its view shows, fewer than
    half of those the target's own outline and creases give at ``obj2cam`` (4, 4, mm) inside the image with nothing in
    front (other parts of the cell, or the image's border, hide the rest)."""
    from calib_core.look.edge_samples import edge_points

    return len(shown) < 0.5 * len(edge_points(mesh, obj2cam, intrinsics, None)[0])


def share_in_view(mesh: trimesh.Trimesh, obj2cam: np.ndarray, intrinsics: Intrinsics, margin_px: float) -> float:
    """The share (0-1) of the mesh's vertices (at most 2000, evenly) in front of a camera at ``obj2cam`` (4, 4, mm) and
    inside its image widened by ``margin_px`` on every side (the search's reach)."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    vertices = vertices[:: max(1, len(vertices) // 2000)]
    z = vertices @ obj2cam[2, :3] + obj2cam[2, 3]
    ahead = z > 1.0
    if not ahead.any():
        return 0.0
    inside = intrinsics.contains(project_points(vertices[ahead], obj2cam, intrinsics), margin_px=-margin_px)
    return float(np.count_nonzero(inside)) / len(vertices)


def seen_unhidden(mesh: trimesh.Trimesh, points: np.ndarray, obj2cam: np.ndarray) -> np.ndarray:
    """Which feature points (n, 3) a camera at ``obj2cam`` sees, not hidden by the mesh itself: no
    triangle crosses the segment from the camera to the point short of it (Moller-Trumbore over every
    triangle, vectorised: features are few and target meshes small)."""
    centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
    tri = mesh.triangles  # (f, 3, 3)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    out = np.ones(len(points), dtype=bool)
    for k, p in enumerate(points):
        d = p - centre
        length = float(np.linalg.norm(d))
        d /= length
        h = np.cross(d, e2)
        a = np.einsum("ij,ij->i", e1, h)
        ok = np.abs(a) > 1e-12
        f = np.where(ok, 1.0 / np.where(ok, a, 1.0), 0.0)
        s = centre - tri[:, 0]
        u = f * np.einsum("ij,ij->i", s, h)
        q = np.cross(s, e1)
        v = f * (q @ d)
        t = f * np.einsum("ij,ij->i", e2, q)
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t < length - 1.0)
        out[k] = not hit.any()
    return out
