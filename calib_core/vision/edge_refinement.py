"""Model-based refinement: the target's CAD edges aligned to the image's gradients (the approach of
RAPID and of ViSP's model-based edge tracker).

Samples every few pixels along the crease edges the camera sees at the current estimate; for each,
the strongest gradient along the edge's normal within a window ("moving edges"); a robust
Gauss-Newton step on the pose that moves every sample along its normal onto its edge (Tukey weights,
scale from the median absolute deviation); the window shrinks as the pose converges. Edges the model
says have no contrast (where a rendered view of the cell, if given, shows no gradient) are left out:
two dark faces meeting make no edge to find, and a search there would lock onto the nearest one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.vision.edge_alignment import crease_segments
from calib_core.vision.feature_detectors import gradient_magnitude, search_normals

_SAMPLE_STEP_PX = 4.0
_MIN_STRENGTH = 12.0
_TUKEY = 4.685


@dataclass(frozen=True)
class EdgeFit:
    """``obj2cam`` (4, 4) the refined pose (mm); ``rms_px`` the weighted RMS of the samples' normal
    offsets; ``sigma_px`` their robust scale; ``samples`` used in the last step; ``covariance`` (6, 6)
    of (rotation vector rad, translation mm) from the last step's normal equations and ``sigma_px``;
    ``converged``; ``edges_px`` (m, 2) the image edge points found, ``offsets_px`` (m,) their offsets
    along the normals and ``residuals_px`` (m, 2) as vectors (image edge minus the model's edge, at the
    pose before the last step), for drawing and for the solution's residuals."""

    obj2cam: np.ndarray
    rms_px: float
    sigma_px: float
    samples: int
    covariance: np.ndarray
    converged: bool
    edges_px: np.ndarray
    offsets_px: np.ndarray
    residuals_px: np.ndarray
    inlier_share: float
    """The share of the model's edge samples that found their image edge in the last step (weight > 0):
    a fit that settled on a few samples (a wrong minimum) has a low one."""

    @property
    def settled(self) -> bool:
        """Converged, the samples within 0.5 px RMS, and at least half of them on their edges."""
        return self.converged and self.rms_px <= 0.5 and self.inlier_share >= 0.5


def silhouette_segments(mesh, centre_mm: np.ndarray) -> np.ndarray:
    """The occluding contour seen from ``centre_mm`` (3,) (mesh frame): edges between a face turned to the
    camera and one turned away, whatever their angle (a pin's round side has no crease). (E, 2, 3) mm."""
    pairs = mesh.face_adjacency
    normals = mesh.face_normals[pairs]  # (E, 2, 3)
    mid = mesh.vertices[mesh.face_adjacency_edges].mean(axis=1)
    toward = np.einsum("eij,ej->ei", normals, centre_mm - mid) > 0
    contour = toward[:, 0] != toward[:, 1]
    return mesh.vertices[mesh.face_adjacency_edges[contour]]


def _edge_points(mesh, obj2cam: np.ndarray, intrinsics: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """3D samples (m, 3) on the visible crease and silhouette edges and their edges' far ends (m, 3), every ~4 px."""
    seg, normals = crease_segments(mesh)
    centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
    facing = np.einsum("eij,ej->ei", normals, centre - seg.mean(axis=1)) > 0
    seg = seg[facing.any(axis=1)]
    silhouette = silhouette_segments(mesh, centre)
    if len(silhouette):
        seg = np.concatenate([seg, silhouette]) if len(seg) else silhouette
    if len(seg) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    ends = project_points(seg.reshape(-1, 3), obj2cam, intrinsics).reshape(-1, 2, 2)
    counts = np.clip(np.floor(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) / _SAMPLE_STEP_PX).astype(int) - 1, 0, 500)
    which = np.repeat(np.arange(len(seg)), counts)
    s = np.concatenate([(np.arange(1, c + 1)) / (c + 1) for c in counts]) if counts.sum() else np.zeros(0)
    pts = seg[which, 0] + (seg[which, 1] - seg[which, 0]) * s[:, None]
    return pts, seg[which, 1]


def model_shows_edge(expected: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Which pixels (m, 2) of the model's view (h, w) lie on a gradient of at least 12 grey levels a pixel."""
    magnitude = gradient_magnitude(expected)
    h, w = magnitude.shape
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < w - 1) & (uv[:, 1] >= 0) & (uv[:, 1] < h - 1)
    u = np.clip(np.rint(uv[:, 0]).astype(int), 0, w - 1)
    v = np.clip(np.rint(uv[:, 1]).astype(int), 0, h - 1)
    return inside & (magnitude[v, u] >= _MIN_STRENGTH)


def _perturbed(obj2cam: np.ndarray, xi: np.ndarray) -> np.ndarray:
    out = obj2cam.copy()
    out[:3, :3] = Rotation.from_rotvec(xi[:3]).as_matrix() @ obj2cam[:3, :3]
    out[:3, 3] = Rotation.from_rotvec(xi[:3]).as_matrix() @ obj2cam[:3, 3] + xi[3:]
    return out


def refine_to_edges(grey: np.ndarray, intrinsics: Intrinsics, mesh, obj2cam: np.ndarray, *, expected: np.ndarray | None = None, search_px: float = 8.0,
                    iterations: int = 30) -> EdgeFit:
    """Refine ``obj2cam`` (the mesh's frame to the camera's, mm) so that the mesh's edges lie on the
    image's; ``expected`` (h, w) the cell rendered at ``obj2cam``, to leave out edges without contrast."""
    magnitude = gradient_magnitude(grey)
    pts, far = _edge_points(mesh, obj2cam, intrinsics)
    if expected is not None and len(pts):
        # where the model's view shows no gradient (two faces of one shade meeting) there is no edge to find
        shows = model_shows_edge(expected, project_points(pts, obj2cam, intrinsics))
        pts, far = pts[shows], far[shows]
    pose = obj2cam.copy()
    window = search_px
    sigma, rms, converged = 1.0, np.inf, False
    H = np.eye(6)
    edges, offsets, vectors = np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2))
    share = 0.0
    previous_xi, damping = None, 1.0
    for it in range(iterations):
        if len(pts) < 12:
            break
        uv = project_points(pts, pose, intrinsics)
        d = project_points(far, pose, intrinsics) - uv
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
        normals = np.column_stack([-d[:, 1], d[:, 0]])
        found, strength, inside = search_normals(magnitude, uv, normals, window)
        ok = inside & (strength >= _MIN_STRENGTH)
        if ok.sum() < 12:
            break
        r = np.einsum("ij,ij->i", found - uv, normals)
        mad = 1.4826 * float(np.median(np.abs(r[ok] - np.median(r[ok]))))
        sigma = max(mad, 0.05)
        c = _TUKEY * sigma
        wts = np.where(ok & (np.abs(r) < c), (1 - (r / c) ** 2) ** 2, 0.0)
        # Jacobian of each sample's normal offset in the pose's six small motions (central differences)
        J = np.empty((len(pts), 6))
        for k in range(6):
            step = np.zeros(6)
            step[k] = 1e-5 if k < 3 else 1e-3
            plus = project_points(pts, _perturbed(pose, step), intrinsics)
            minus = project_points(pts, _perturbed(pose, -step), intrinsics)
            J[:, k] = np.einsum("ij,ij->i", (plus - minus) / (2 * step[k]), normals)
        H = J.T @ (wts[:, None] * J)
        g = J.T @ (wts * r)
        try:
            xi = np.linalg.solve(H + 1e-9 * np.eye(6) * np.trace(H), g)
        except np.linalg.LinAlgError:
            break
        if previous_xi is not None and xi @ H @ previous_xi < -0.5 * (xi @ H @ xi):
            # The step turned back on the last one: samples jumping between two pixels (an aliased or
            # quantised edge) make a two-cycle that plain Gauss-Newton never leaves. Halve the steps
            # from here on, and the pose settles between the two.
            damping *= 0.5
        previous_xi = xi
        xi = damping * xi
        pose = _perturbed(pose, xi)
        rms = float(np.sqrt(np.sum(wts * r**2) / max(np.sum(wts), 1e-9)))
        edges, offsets, vectors = found[ok], r[ok], (r[:, None] * normals)[ok]
        share = float(np.mean(wts > 0))
        moved_px = float(np.max(np.abs(J @ xi))) if len(J) else 0.0
        at_finest = window <= 2.0
        window = max(2.0, min(0.7 * window, 3.0 * sigma + 1.0))  # coarse to fine: wrong matches fall away as it shrinks
        # Settled when the samples stop moving; at the finest window a step under a tenth of the
        # noise is samples trading places at the window's rim (a cycle, not a descent).
        if it > 0 and (moved_px < 0.01 or (at_finest and moved_px < 0.1 * sigma)):
            converged = True
            break
    try:
        covariance = sigma**2 * np.linalg.inv(H)
    except np.linalg.LinAlgError:
        covariance = np.full((6, 6), np.nan)
    return EdgeFit(pose, rms, sigma, len(offsets), covariance, converged, edges, offsets, vectors, share)
