"""The occluding contour of any mesh at a pose: where the object meets its background in the image.

A CAD part's outline runs along long crease edges, each of which holds many samples; a scanned object (a
smooth mesh of 10-25 thousand facets, as BOP's and YCB's models are) has no crease, and its outline is made of
facet edges a fraction of a pixel long, none long enough to hold a sample. Here the outline is taken from the
object's own silhouette: the mesh's faces are filled into a mask at the pose, the mask's outer boundary is
walked every few pixels, and each boundary sample takes the 3D point of the nearest rim edge (an edge between a
face turned to the camera and one turned away). The image point is that 3D point's projection, so the sample
sits on the geometric rim, not on the mask's pixel grid. A rim moves over a smooth surface as the pose changes:
the samples are for the pose they were taken at, and a fit takes them again as it moves.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.spatial import cKDTree

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

NEAR_MM = 1.0
"""Faces with a vertex nearer the camera than this (or behind it) are not filled in."""
_RIM_STEP_PX = 1.0
_SMALL_FACE_PX2 = 2.0
_MATCH_PX = 2.5
_BORDER_PX = 3.0
CHAIN_SAMPLES = 12
"""Consecutive outline samples taken as one edge chain (what the image does to a stretch of outline, its
background and its shading, is shared by its neighbours): about 50 px of outline at the default step."""


@dataclass(frozen=True)
class Outline:
    """Samples on the occluding contour: ``points_mm`` (m, 3) and ``along_mm`` (m, 3), a point a little
    further along the contour (the edge's direction, as a crease sample's far end gives it), both in the
    mesh's frame; ``chain`` (m,) the stretch of contour each belongs to."""

    points_mm: np.ndarray
    along_mm: np.ndarray
    chain: np.ndarray

    @staticmethod
    def empty() -> "Outline":
        return Outline(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=int))

    def __len__(self) -> int:
        return len(self.points_mm)


def silhouette_segments(mesh, centre_mm: np.ndarray) -> np.ndarray:
    """The occluding contour seen from ``centre_mm`` (3,) (mesh frame): edges between a face turned to the
    camera and one turned away, whatever their angle (a pin's round side has no crease). (E, 2, 3) mm."""
    normals, mid, edges = _adjacency(mesh)
    # n . (c - m) for both faces of every edge, as n . c - n . m (the second kept for the mesh's life)
    # (as one (2E, 3) product: a stack of (2, 3) ones costs ten times as much)
    facing = (normals.reshape(-1, 3) @ np.asarray(centre_mm, dtype=float)).reshape(-1, 2) - mid
    toward = facing > 0
    contour = toward[:, 0] != toward[:, 1]
    return edges[contour]


_ADJACENCY: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}


def _adjacency(mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For every edge between two faces: the faces' normals (E, 2, 3), each normal's dot with the edge's midpoint
    (E, 2) and the edge's ends (E, 2, 3) mm. Kept for the mesh's life: a fit asks for its rim at every resampling,
    and gathering them took 10 ms a call for a scanned mesh. (A mesh is not changed in place here.)"""
    key = id(mesh)
    if key not in _ADJACENCY:
        normals = np.asarray(mesh.face_normals)[mesh.face_adjacency]
        edges = np.asarray(mesh.vertices)[mesh.face_adjacency_edges]
        mid = edges.mean(axis=1)
        _ADJACENCY[key] = (normals, np.einsum("eij,ej->ei", normals, mid), edges)
        weakref.finalize(mesh, _ADJACENCY.pop, key, None)
    return _ADJACENCY[key]


_FACE_PLANES: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _face_planes(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Every face's normal (F, 3) and its dot with the face's first corner (F,): a face is turned to a camera at ``c``
    when ``n . c - n . p0 > 0``. Kept for the mesh's life (as :func:`_adjacency`): a fit asks for its silhouette at
    every resampling, and gathering the corners cost a scanned mesh 0.8 ms a call."""
    key = id(mesh)
    if key not in _FACE_PLANES:
        normals = np.asarray(mesh.face_normals, dtype=float)
        first = np.asarray(mesh.vertices, dtype=float)[np.asarray(mesh.faces)[:, 0]]
        _FACE_PLANES[key] = (normals, np.einsum("fi,fi->f", normals, first))
        weakref.finalize(mesh, _FACE_PLANES.pop, key, None)
    return _FACE_PLANES[key]


def silhouette_mask(mesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> tuple[np.ndarray, tuple[int, int]]:
    """The mesh's faces turned to the camera, filled: a uint8 mask over the part of the image the object
    covers (255 inside) and its top-left pixel (u0, v0). Faces reaching behind :data:`NEAR_MM` are left out."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    depth = vertices @ obj2cam[2, :3] + obj2cam[2, 3]
    near = depth > NEAR_MM
    uv = project_points(vertices, obj2cam, intrinsics)
    if near.all():
        few = _faces_maybe_large(mesh, float(depth.min()), intrinsics)
        if few is not None:
            return _splatted(mesh, uv, obj2cam, intrinsics, few)
    faces = np.asarray(mesh.faces)
    normals, offsets = _face_planes(mesh)
    centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
    fine = near & np.isfinite(uv[:, 0]) & np.isfinite(uv[:, 1])  # (per vertex: a face keeps three)
    keep = (normals @ centre - offsets > 0) & fine[faces[:, 0]] & fine[faces[:, 1]] & fine[faces[:, 2]]
    if not keep.any():
        return np.zeros((0, 0), np.uint8), (0, 0)
    kept = faces[keep]
    tri = uv[kept]  # (F, 3, 2)
    u, v = tri[..., 0], tri[..., 1]  # (each extreme taken alone: a reduction over an axis of two is slow)
    lo = np.floor(np.clip([u.min(), v.min()], 0, [intrinsics.width - 1, intrinsics.height - 1])).astype(int) - 2
    hi = np.ceil(np.clip([u.max(), v.max()], 0, [intrinsics.width - 1, intrinsics.height - 1])).astype(int) + 3
    lo = np.maximum(lo, 0)
    hi = np.minimum(hi, [intrinsics.width, intrinsics.height])
    mask = np.zeros((max(hi[1] - lo[1], 1), max(hi[0] - lo[0], 1)), np.uint8)
    # One convex fill a face (a single fillPoly of many polygons fills by the even-odd rule, and overlapping facets
    # would cancel out), with sub-pixel vertices (4 fractional bits) to keep thin facets. A scanned mesh's facets
    # are mostly under a pixel: those are set as their corners' pixels and the gaps closed (3 x 3), 20 ms less a
    # mask for a 20k-face mesh; the outline's samples take their places from the rim edges, not from the mask.
    edge_a, edge_b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    area = 0.5 * np.abs(edge_a[:, 0] * edge_b[:, 1] - edge_a[:, 1] * edge_b[:, 0])
    large = area >= _SMALL_FACE_PX2
    for f in np.round((tri[large] - lo) * 16.0).astype(np.int32):
        cv2.fillConvexPoly(mask, f, 255, lineType=cv2.LINE_8, shift=4)
    if not large.all():
        small = np.zeros(len(vertices), dtype=bool)
        small[kept[~large]] = True  # each corner once (a vertex is the corner of six faces)
        corners = np.rint(uv[small] - lo).astype(int)
        corners = corners[
            (corners[:, 0] >= 0)
            & (corners[:, 0] < mask.shape[1])
            & (corners[:, 1] >= 0)
            & (corners[:, 1] < mask.shape[0])
        ]
        mask[corners[:, 1], corners[:, 0]] = 255
        mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    return mask, (int(lo[0]), int(lo[1]))


_FACES_BY_AREA: dict[int, tuple[np.ndarray, np.ndarray]] = {}
_FEW_LARGE = 0.1
"""The largest share of a mesh's faces that may be large for :func:`_splatted` to draw its silhouette."""


def _faces_maybe_large(mesh, nearest_mm: float, intrinsics: Intrinsics) -> np.ndarray | None:
    """The faces (k,) that may cover :data:`_SMALL_FACE_PX2` or more in the image with every vertex at least
    ``nearest_mm`` deep, or None when they are more than a tenth of the mesh's (a CAD part's: filled face by face as
    before). A face's image is at most its area (mm^2) times ``fu fv / z^2``, and half as much again seen off the
    optical axis (its image grows with the line of sight's length: 1.2 times at the corner of a 60 deg view)."""
    key = id(mesh)
    if key not in _FACES_BY_AREA:
        areas = np.asarray(mesh.area_faces, dtype=float)
        order = np.argsort(-areas, kind="stable")
        _FACES_BY_AREA[key] = (areas[order], order)
        weakref.finalize(mesh, _FACES_BY_AREA.pop, key, None)
    areas, order = _FACES_BY_AREA[key]
    smallest_large_mm2 = _SMALL_FACE_PX2 * nearest_mm**2 / (1.5 * intrinsics.fu * intrinsics.fv)
    count = int(np.searchsorted(-areas, -smallest_large_mm2, side="right"))
    return order[:count] if count <= _FEW_LARGE * len(areas) else None


def _splatted(
    mesh, uv: np.ndarray, obj2cam: np.ndarray, intrinsics: Intrinsics, large: np.ndarray
) -> tuple[np.ndarray, tuple[int, int]]:
    """:func:`silhouette_mask` of a mesh nearly all of whose faces cover under :data:`_SMALL_FACE_PX2` (a scanned
    object's): every vertex's pixel set, the gaps closed (3 x 3), and the few ``large`` faces (k,) turned to the camera
    filled. The vertices of the faces turned away lie inside the silhouette too (every point of a closed object does),
    so all are set and the small faces are never gathered (4 ms a call for a 40k-face mesh, 1 ms this way)."""
    # (column by column: numpy reduces over an axis of two ten times slower than along one)
    u, v = uv[:, 0], uv[:, 1]
    fine = np.isfinite(u) & np.isfinite(v)
    if not fine.all():
        if not fine.any():
            return np.zeros((0, 0), np.uint8), (0, 0)
        u, v = u[fine], v[fine]
    lo = np.maximum(
        np.floor(np.clip([u.min(), v.min()], 0, [intrinsics.width - 1, intrinsics.height - 1])).astype(int) - 2, 0
    )
    hi = np.ceil(np.clip([u.max(), v.max()], 0, [intrinsics.width - 1, intrinsics.height - 1])).astype(int) + 3
    hi = np.minimum(hi, [intrinsics.width, intrinsics.height])
    mask = np.zeros((max(hi[1] - lo[1], 1), max(hi[0] - lo[0], 1)), np.uint8)
    col, row = np.rint(u - lo[0]).astype(np.intp), np.rint(v - lo[1]).astype(np.intp)
    within = (col >= 0) & (col < mask.shape[1]) & (row >= 0) & (row < mask.shape[0])
    mask[row[within], col[within]] = 255
    mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
    if len(large):
        faces = np.asarray(mesh.faces)[large]
        normals, offsets = _face_planes(mesh)
        centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
        turned = normals[large] @ centre - offsets[large] > 0
        turned &= fine[faces[:, 0]] & fine[faces[:, 1]] & fine[faces[:, 2]]
        for f in np.round((uv[faces[turned]] - lo) * 16.0).astype(np.int32):
            cv2.fillConvexPoly(mask, f, 255, lineType=cv2.LINE_8, shift=4)
    return mask, (int(lo[0]), int(lo[1]))


def _rim_points(
    mesh, obj2cam: np.ndarray, intrinsics: Intrinsics, rims: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Points (k, 3) mm along the rim edges (``rims`` (E, 2, 3) when the caller has them), about a pixel apart in
    the image, and their pixels (k, 2)."""
    seg = silhouette_segments(mesh, -obj2cam[:3, :3].T @ obj2cam[:3, 3]) if rims is None else rims
    if not len(seg):
        return np.zeros((0, 3)), np.zeros((0, 2))
    z = seg @ obj2cam[2, :3] + obj2cam[2, 3]
    seg = seg[(z > NEAR_MM).all(axis=1)]
    if not len(seg):
        return np.zeros((0, 3)), np.zeros((0, 2))
    ends = project_points(seg.reshape(-1, 3), obj2cam, intrinsics).reshape(-1, 2, 2)
    counts = np.clip(np.ceil(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) / _RIM_STEP_PX).astype(int), 1, 4000) + 1
    which = np.repeat(np.arange(len(seg)), counts)
    # each segment's 0, 1/(c-1), ..., 1 at once (a linspace a segment took 13 ms a call on a scanned mesh's rim)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    s = (np.arange(len(which)) - first) / (counts[which] - 1.0)
    points = seg[which, 0] + (seg[which, 1] - seg[which, 0]) * s[:, None]
    return points, project_points(points, obj2cam, intrinsics)


def outline_samples(
    mesh,
    obj2cam: np.ndarray,
    intrinsics: Intrinsics,
    step_px: float = 4.0,
    silhouette=None,
    rims: np.ndarray | None = None,
) -> Outline:
    """Samples every ``step_px`` along the outer boundary of the mesh's silhouette at ``obj2cam`` (4, 4: the
    mesh's frame to the camera's, mm), each on the rim edge nearest its boundary pixel (within 2.5 px); none
    where the image's border cuts the silhouette (the border is not the object's edge). ``silhouette``: the
    :func:`silhouette_mask` at that pose, and ``rims`` its rim edges (E, 2, 3), when the caller has them."""
    mask, (u0, v0) = silhouette_mask(mesh, obj2cam, intrinsics) if silhouette is None else silhouette
    if mask.size == 0 or not mask.any():
        return Outline.empty()
    rim, rim_px = _rim_points(mesh, obj2cam, intrinsics, rims)
    if not len(rim):
        return Outline.empty()
    tree = cKDTree(rim_px)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    points, along, chain = [], [], []
    next_chain = 0
    for contour in contours:
        c = contour[:, 0, :].astype(float) + [u0, v0]
        if len(c) < 8:
            continue
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
        picks = np.searchsorted(arc, np.arange(0.0, arc[-1], step_px))
        picks = picks[picks < len(c)]
        px = c[picks]
        inside = (
            (px[:, 0] > _BORDER_PX)
            & (px[:, 0] < intrinsics.width - 1 - _BORDER_PX)
            & (px[:, 1] > _BORDER_PX)
            & (px[:, 1] < intrinsics.height - 1 - _BORDER_PX)
        )
        distance, nearest = tree.query(px)
        good = inside & (distance <= _MATCH_PX)
        # runs of good samples, each walked in order: a sample's direction is toward its neighbour
        n = len(px)
        for run in _runs(good, closed=True):
            if len(run) < 3:
                continue
            p = rim[nearest[run]]
            ahead = np.roll(p, -1, axis=0)
            closed_loop = len(run) == n
            if not closed_loop:
                ahead[-1] = p[-1] + (p[-1] - p[-2])
            points.append(p)
            along.append(ahead)
            chain.append(next_chain + np.arange(len(run)) // CHAIN_SAMPLES)
            next_chain = int(chain[-1].max()) + 1
    if not points:
        return Outline.empty()
    points, along, chain = np.concatenate(points), np.concatenate(along), np.concatenate(chain)
    # two neighbours on one rim point give no direction
    moved = np.linalg.norm(along - points, axis=1) > 1e-9
    return Outline(points[moved], along[moved], chain[moved])


def _runs(good: np.ndarray, closed: bool) -> list[np.ndarray]:
    """Index runs (in order) where ``good`` holds; on a closed contour a run may wrap past the end."""
    n = len(good)
    if good.all():
        return [np.arange(n)]
    if not good.any():
        return []
    start = int(np.flatnonzero(~good)[0]) + 1 if closed else 0
    order = (np.arange(n) + start) % n if closed else np.arange(n)
    runs, current = [], []
    for i in order:
        if good[i]:
            current.append(i)
        elif current:
            runs.append(np.array(current))
            current = []
    if current:
        runs.append(np.array(current))
    return runs
