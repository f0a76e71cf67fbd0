"""How well a scanned mesh's own colours agree with a photo at a pose: a check of an answer against the annotation
that neither the look nor the annotation was made from.

The look fits the object's outline and edges and never reads the colours a scan gives each vertex; at two poses
a few pixels apart (the look's answer and the data set's annotation), the one at which the object's colours lie on
the photo's is the one the photo's inside of the object supports. The agreement is the normalised cross-correlation
of the vertices' grey with the photo's (lightly blurred) under them, over the vertices the camera sees at least
:data:`INSIDE_PX` inside the object's outline (the outline's pixels mix the surroundings in).
"""

from __future__ import annotations

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

INSIDE_PX = 3.0
"""Vertices nearer the object's outline in the image than this (px) are left out."""
FACING = 0.2
"""A vertex counts as seen when its normal turns at least this much (cosine) towards the camera."""
HIDDEN_MM = 3.0
"""... and it lies within this of the nearest surface the camera sees at its pixel (a splatted depth buffer)."""
BLUR_PX = 1.0
"""The photo's blur (Gaussian sigma, px) before it is read under the vertices: a scan's colours are of patches."""


def vertex_grey(mesh) -> np.ndarray | None:
    """The mesh's vertex colours as grey (n,) 0-255, or None when it has none."""
    colours = getattr(getattr(mesh, "visual", None), "vertex_colors", None)
    if colours is None or len(colours) != len(mesh.vertices) or getattr(mesh.visual, "kind", None) != "vertex":
        return None
    return np.asarray(colours, dtype=float)[:, :3] @ np.array([0.299, 0.587, 0.114])


def seen_inside(mesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """The pixels (n, 2) of the mesh's vertices at ``obj2cam`` (4, 4, mm) and which of them (n,) bool the camera sees
    at least :data:`INSIDE_PX` inside the object's outline."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    X = vertices @ obj2cam[:3, :3].T + obj2cam[:3, 3]
    normals = np.asarray(mesh.vertex_normals, dtype=float) @ obj2cam[:3, :3].T
    facing = np.einsum("ij,ij->i", normals, -X / np.linalg.norm(X, axis=1, keepdims=True)) > FACING
    uv = project_points(vertices, obj2cam, intrinsics)
    h, w = intrinsics.height, intrinsics.width
    px = np.round(np.where(np.isfinite(uv), uv, -1.0)).astype(int)  # (a point behind the camera has no pixel)
    on_image = (px[:, 0] >= 0) & (px[:, 0] < w) & (px[:, 1] >= 0) & (px[:, 1] < h) & (X[:, 2] > 0)
    idx = np.flatnonzero(on_image)
    depth = np.full((h, w), np.inf, np.float32)
    np.minimum.at(depth, (px[idx, 1], px[idx, 0]), X[idx, 2])
    depth = cv2.erode(depth, np.ones((3, 3), np.uint8))  # a vertex behind a surface may fall between its vertices
    mask = np.zeros((h, w), np.uint8)
    mask[px[idx, 1], px[idx, 0]] = 1
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    inside = cv2.distanceTransform(mask, cv2.DIST_L2, 3)
    seen = on_image & facing
    seen[idx] &= (X[idx, 2] <= depth[px[idx, 1], px[idx, 0]] + HIDDEN_MM) & (
        inside[px[idx, 1], px[idx, 0]] >= INSIDE_PX
    )
    return uv, seen


def colour_agreement(image_rgb: np.ndarray, mesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> float | None:
    """The normalised cross-correlation (-1..1) of the mesh's vertex colours with ``image_rgb`` (h, w, 3) uint8 at
    ``obj2cam`` (4, 4, mm), over the vertices seen inside the outline; None when the mesh has no vertex colours or
    fewer than 50 vertices are seen."""
    grey_vertices = vertex_grey(mesh)
    if grey_vertices is None:
        return None
    uv, seen = seen_inside(mesh, obj2cam, intrinsics)
    if seen.sum() < 50:
        return None
    grey = cv2.GaussianBlur(cv2.cvtColor(image_rgb, cv2.COLOR_RGB2GRAY).astype(np.float32), (0, 0), BLUR_PX)
    under = cv2.remap(
        grey, uv[seen, 0].astype(np.float32)[:, None], uv[seen, 1].astype(np.float32)[:, None], cv2.INTER_LINEAR
    )[:, 0]
    a, b = under - under.mean(), grey_vertices[seen] - grey_vertices[seen].mean()
    return float(a @ b / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-9))
