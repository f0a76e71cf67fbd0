"""The samples an edge fit measures: points every few pixels along the edges of a mesh that a camera at a pose
sees (its crease edges with a face turned to the camera, its rim, and its occluding contour where its own edges are
too short to hold a sample), each with its edge's direction, its clearance from the other edges, its chain (samples
whose offsets an image's lighting or a bevel moves together) and its side of the object (whether it lies on the
outline). :mod:`calib_core.look.edge_refinement` fits them to an image.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look.edge_alignment import crease_segments
from calib_core.look.outline import outline_samples, silhouette_mask, silhouette_segments

SAMPLE_STEP_PX = 4.0
"""A sample every this many pixels along an edge."""
MIN_STRENGTH = 12.0
"""The least gradient (grey levels a pixel) an edge is taken to show."""
_CROWDED_PX = 3.0

OUTLINE_ONLY_WHEN_UNCOVERED = 0.5
"""The contour's samples join the mesh's own edge samples only when more than this share of them lies away from
any (a scanned mesh's outline: none of its facet edges holds a sample)."""


def _segment_keys(seg: np.ndarray) -> np.ndarray:
    """One key per segment (E, 2, 3), the same for both directions (to 1 um): (E, 6) int64, its ends in
    lexicographic order."""
    ends = np.round(seg * 1000.0).astype(np.int64)
    a, b = ends[:, 0], ends[:, 1]
    differs = a != b
    first = np.argmax(differs, axis=1)  # the first coordinate where the ends differ decides their order
    rows = np.arange(len(ends))
    flip = differs.any(axis=1) & (a[rows, first] > b[rows, first])
    ordered = np.where(flip[:, None, None], ends[:, ::-1], ends)
    return ordered.reshape(len(ends), 6)


def _rows_in(rows: np.ndarray, known: np.ndarray) -> np.ndarray:
    """Which of ``rows`` (n, k) int64 appear among ``known`` (m, k)."""
    if not len(known) or not len(rows):
        return np.zeros(len(rows), dtype=bool)
    view = np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))
    return np.isin(np.ascontiguousarray(rows).view(view).ravel(), np.ascontiguousarray(known).view(view).ravel())


def visible_segments(mesh, obj2cam: np.ndarray, silhouette: np.ndarray | None = None) -> np.ndarray:
    """The crease edges with a face turned to the camera and the silhouette, each once: (E, 2, 3) mm
    (a crease on the occluding contour is both; sampled twice, its samples would count double).
    ``silhouette``: :func:`silhouette_segments` from this pose's camera, when the caller has them."""
    seg, normals = crease_segments(mesh)
    centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
    facing = np.einsum("eij,ej->ei", normals, centre - seg.mean(axis=1)) > 0
    seg = seg[facing.any(axis=1)]
    silhouette = silhouette_segments(mesh, centre) if silhouette is None else silhouette
    if len(silhouette):
        known = _segment_keys(seg) if len(seg) else np.zeros((0, 6), np.int64)
        new = ~_rows_in(_segment_keys(silhouette), known)
        seg = np.concatenate([seg, silhouette[new]]) if len(seg) else silhouette
    return seg


_CHAIN_TURN_DEG = 35.0


def _same_points(ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For integer points (n, 3): each one's number among the distinct points (n,), in lexicographic order, and how
    many times each distinct point occurs, as ``np.unique(ends, axis=0, return_inverse=True, return_counts=True)``
    gives them. Within 2 m (in um) each point packs into one integer whose order is the rows' (a unique of rows
    sorts them as raw bytes, 1.5 ms for a scanned mesh's rim, a sixth of a resampling)."""
    shifted = ends - ends.min(axis=0)
    if len(ends) and int(shifted.max()) < 1 << 21:
        keys = (shifted[:, 0] << 42) | (shifted[:, 1] << 21) | shifted[:, 2]
        _, point, counts = np.unique(keys, return_inverse=True, return_counts=True)
    else:
        _, point, counts = np.unique(ends, axis=0, return_inverse=True, return_counts=True)
    return point.ravel(), counts


def edge_chains(seg: np.ndarray) -> np.ndarray:
    """One chain number (E,) per segment (E, 2, 3): segments joined end to end where exactly two meet
    and turn by less than 35 deg (a rim's facets make one chain; a plate's edges meet at corners and
    stay apart). A chain's samples share what the image does to that edge (its lighting, its bevel), so
    their offsets are not independent."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(seg)
    if n == 0:
        return np.zeros(0, dtype=int)
    ends = np.round(seg * 1000.0).astype(np.int64).reshape(-1, 3)  # to 1 um; slot i is segment i // 2, end i % 2
    point, counts = _same_points(ends)
    shared = np.flatnonzero(counts[point] == 2)  # the ends where exactly two segments meet
    shared = shared[np.argsort(point[shared], kind="stable")]
    first, second = shared[0::2], shared[1::2]
    a, ka, b, kb = first // 2, first % 2, second // 2, second % 2
    da = seg[a, 1 - ka] - seg[a, ka]  # both pointing away from the shared end
    db = seg[b, 1 - kb] - seg[b, kb]
    cos = -np.einsum("ij,ij->i", da, db) / np.maximum(np.linalg.norm(da, axis=1) * np.linalg.norm(db, axis=1), 1e-12)
    join = cos > np.cos(np.radians(_CHAIN_TURN_DEG))
    graph = coo_matrix((np.ones(int(join.sum())), (a[join], b[join])), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def edge_points(
    mesh, obj2cam: np.ndarray, intrinsics: Intrinsics, expected_magnitude: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """3D samples (m, 3) on the visible crease and silhouette edges and on the occluding contour, their edges'
    far ends (m, 3), their clearance (m,) px and their :func:`edge_chains` numbers (m,), every ~4 px. With
    ``expected_magnitude`` (h, w: the :func:`gradient_magnitude` of the cell rendered at ``obj2cam``)
    only where that view shows an edge and no other edge it shows passes within :data:`_CROWDED_PX`
    (:func:`_clearance`). The contour (:mod:`calib_core.look.outline`) fills in where the mesh's own edges
    are too short to hold a sample: a scanned object's facets, a fine rim."""
    samples = edge_model(mesh, obj2cam, intrinsics, expected_magnitude)
    return samples.points, samples.far, samples.clearance, samples.chain


@dataclass(frozen=True)
class EdgeSamples:
    """What :func:`edge_model` gives: the samples ``points`` (m, 3, mm, the mesh's frame), their edges' ``far``
    ends (m, 3), ``clearance`` (m,) px, ``chain`` (m,); ``outward`` (m,): +1 or -1 where the sample lies on the
    object's outline (the side the normal from ``points`` to ``far``, turned a quarter left in the image, must
    be multiplied by to point away from the object), 0 on an edge with the object on both sides; ``from_outline``
    how many samples (the last ones) came from the occluding contour alone (they belong to this pose: a smooth
    surface's rim moves with it); ``silhouette``: the object's mask at this pose and its top-left pixel."""

    points: np.ndarray
    far: np.ndarray
    clearance: np.ndarray
    chain: np.ndarray
    outward: np.ndarray
    from_outline: int
    silhouette: tuple[np.ndarray, tuple[int, int]]


def edge_model(
    mesh,
    obj2cam: np.ndarray,
    intrinsics: Intrinsics,
    expected_magnitude: np.ndarray | None = None,
    *,
    whole_outline: bool = False,
) -> EdgeSamples:
    """The samples of :func:`edge_points`, with which of them lie on the outline (:class:`EdgeSamples`).
    ``whole_outline``: the contour's samples fill every gap the mesh's own edges leave (for a fit of the outline by
    colour); else only on a mesh whose own edges hold little of its outline (:data:`OUTLINE_ONLY_WHEN_UNCOVERED`)."""
    rims = silhouette_segments(mesh, -obj2cam[:3, :3].T @ obj2cam[:3, 3])
    pts, far, clearance, chain = _crease_points(mesh, obj2cam, intrinsics, expected_magnitude, rims)
    silhouette = silhouette_mask(mesh, obj2cam, intrinsics)
    outline = outline_samples(mesh, obj2cam, intrinsics, SAMPLE_STEP_PX, silhouette=silhouette, rims=rims)
    added = 0
    if len(outline):
        uv = project_points(outline.points_mm, obj2cam, intrinsics)
        if len(pts):
            # where a crease or silhouette sample lies within a step, the contour adds nothing; and where the mesh's
            # own edges hold most of its outline (a CAD part), the contour adds nothing at all: its few uncovered
            # samples are corners and short facets, and the CAD fit is kept as it was
            keep = cKDTree(project_points(pts, obj2cam, intrinsics)).query(uv)[0] > SAMPLE_STEP_PX + 0.5
            if not whole_outline and keep.mean() < OUTLINE_ONLY_WHEN_UNCOVERED:
                keep[:] = False
        else:
            keep = np.ones(len(uv), dtype=bool)
        if expected_magnitude is not None:
            keep &= model_shows_edge(expected_magnitude, uv)
        if keep.any():
            first_chain = int(chain.max()) + 1 if len(chain) else 0
            pts, far = np.concatenate([pts, outline.points_mm[keep]]), np.concatenate([far, outline.along_mm[keep]])
            clearance = np.concatenate([clearance, np.full(int(keep.sum()), np.inf)])
            chain = np.concatenate([chain, first_chain + outline.chain[keep]])
            added = int(keep.sum())
    return EdgeSamples(
        pts, far, clearance, chain, _outward(pts, far, obj2cam, intrinsics, silhouette), added, silhouette
    )


_SIDE_PX = 3.0


def _outward(pts: np.ndarray, far: np.ndarray, obj2cam: np.ndarray, intrinsics: Intrinsics, silhouette) -> np.ndarray:
    """+1 or -1 (m,) where the object lies on one side of a sample only (3 px across), 0 where on both or neither."""
    mask, (u0, v0) = silhouette
    if not len(pts) or mask.size == 0:
        return np.zeros(len(pts), dtype=int)
    uv = project_points(pts, obj2cam, intrinsics)
    d = project_points(far, obj2cam, intrinsics) - uv
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
    normals = np.column_stack([-d[:, 1], d[:, 0]])

    def on_object(points):
        u = np.rint(points[:, 0] - u0).astype(int)
        v = np.rint(points[:, 1] - v0).astype(int)
        within = (u >= 0) & (u < mask.shape[1]) & (v >= 0) & (v < mask.shape[0])
        out = np.zeros(len(points), dtype=bool)
        out[within] = mask[v[within], u[within]] > 0
        return out

    plus, minus = on_object(uv + _SIDE_PX * normals), on_object(uv - _SIDE_PX * normals)
    return np.where(minus & ~plus, 1, np.where(plus & ~minus, -1, 0))


def _crease_points(
    mesh,
    obj2cam: np.ndarray,
    intrinsics: Intrinsics,
    expected_magnitude: np.ndarray | None,
    rims: np.ndarray | None = None,
):
    """:func:`edge_points` along the mesh's own crease and silhouette edges (``rims``: the silhouette's, when known)."""
    if _longest_edge_px(mesh, obj2cam, intrinsics) < 2.0 * SAMPLE_STEP_PX:
        # no edge of the mesh can hold a sample (a scanned mesh's facets): none gathered (a tenth of a fit's time)
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=int)
    seg = visible_segments(mesh, obj2cam, rims)
    if len(seg) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=int)
    ends = project_points(seg.reshape(-1, 3), obj2cam, intrinsics).reshape(-1, 2, 2)
    counts = np.clip(np.floor(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) / SAMPLE_STEP_PX).astype(int) - 1, 0, 500)
    if not counts.any():
        # no edge long enough to hold a sample (a scanned mesh's facets): its chains are not needed
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=int)
    which = np.repeat(np.arange(len(seg)), counts)
    s = np.concatenate([(np.arange(1, c + 1)) / (c + 1) for c in counts]) if counts.sum() else np.zeros(0)
    pts = seg[which, 0] + (seg[which, 1] - seg[which, 0]) * s[:, None]
    far = seg[which, 1]
    chain = edge_chains(seg)[which]
    if expected_magnitude is None or len(pts) == 0:
        return pts, far, np.full(len(pts), np.inf), chain
    uv = project_points(pts, obj2cam, intrinsics)
    # where the model's view shows no gradient (two faces of one shade meeting, an edge hidden behind a
    # face) there is no edge to find, and a search there would lock onto the nearest one
    shows = model_shows_edge(expected_magnitude, uv)
    # the edges that can crowd a sample: those the model's view shows (a rim's facets, too short to
    # hold a sample, by their midpoints)
    sampled = np.bincount(which, minlength=len(seg))
    shown = np.where(
        sampled > 0,
        np.bincount(which[shows], minlength=len(seg)) >= 0.5 * sampled,
        model_shows_edge(expected_magnitude, project_points(seg.mean(axis=1), obj2cam, intrinsics)),
    )
    clearance = _clearance(uv, ends[shown], np.searchsorted(np.flatnonzero(shown), which), shown[which])
    keep = shows & (clearance > _CROWDED_PX)
    return pts[keep], far[keep], clearance[keep], chain[keep]


_LONGEST_EDGE: dict[int, float] = {}


def _longest_edge_px(mesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> float:
    """A bound on the image length (px) of the mesh's longest edge at ``obj2cam``: its length (mm) times the focal
    length over the depth of the mesh's nearest vertex, and half as much again off the optical axis. Kept for the mesh's
    life (a mesh is not changed in place here)."""
    key = id(mesh)
    if key not in _LONGEST_EDGE:
        lengths = np.asarray(mesh.edges_unique_length, dtype=float)
        _LONGEST_EDGE[key] = float(lengths.max()) if len(lengths) else 0.0
        weakref.finalize(mesh, _LONGEST_EDGE.pop, key, None)
    vertices = np.asarray(mesh.vertices, dtype=float)
    nearest = float(np.min(vertices @ obj2cam[2, :3])) + float(obj2cam[2, 3]) if len(vertices) else 0.0
    if nearest <= 1.0:
        return np.inf
    return 1.5 * _LONGEST_EDGE[key] * max(intrinsics.fu, intrinsics.fv) / nearest


def _clearance(uv: np.ndarray, ends_px: np.ndarray, own: np.ndarray, own_listed: np.ndarray) -> np.ndarray:
    """How far (m,) px along its normal each sample (m, 2) px is from another projected edge
    (``ends_px`` (E, 2, 2); ``own`` (m,) each sample's own among them where ``own_listed``); inf where
    none crosses its normal. A search wider than that cannot tell the two apart: a plate's front and
    back top edges 3 px apart seen at a grazing angle lock both onto the stronger one (found 2 px and
    1.2 px off, all along them); a boss's rim 4 px inside its base circle, onto the base."""
    if len(ends_px) == 0:
        return np.full(len(uv), np.inf)
    a, b = ends_px[:, 0], ends_px[:, 1]  # (E, 2)
    own = np.clip(own, 0, len(ends_px) - 1)
    d = ends_px[own, 1] - ends_px[own, 0]
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
    n = np.column_stack([-d[:, 1], d[:, 0]])  # (m, 2)
    # the line uv + t n meets the segment a + s (b - a): solve [n, a - b] (t, s) = a - uv
    e = b - a  # (E, 2)
    det = n[:, None, 0] * (-e[None, :, 1]) - n[:, None, 1] * (-e[None, :, 0])  # (m, E)
    rhs = a[None] - uv[:, None]  # (m, E, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (rhs[..., 0] * (-e[None, :, 1]) - rhs[..., 1] * (-e[None, :, 0])) / det
        s = (n[:, None, 0] * rhs[..., 1] - n[:, None, 1] * rhs[..., 0]) / det
    meets = np.isfinite(t) & (np.abs(det) > 1e-9) & (s >= 0) & (s <= 1)
    rows = np.flatnonzero(own_listed)
    meets[rows, own[rows]] = False
    return np.where(meets, np.abs(t), np.inf).min(axis=1)


def model_shows_edge(magnitude: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Which pixels (m, 2) of the model's view lie on a gradient of at least 12 grey levels a pixel
    (``magnitude`` (h, w): the view's :func:`gradient_magnitude`, computed once per render)."""
    h, w = magnitude.shape
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < w - 1) & (uv[:, 1] >= 0) & (uv[:, 1] < h - 1)
    u = np.clip(np.rint(uv[:, 0]).astype(int), 0, w - 1)
    v = np.clip(np.rint(uv[:, 1]).astype(int), 0, h - 1)
    return inside & (magnitude[v, u] >= MIN_STRENGTH)
