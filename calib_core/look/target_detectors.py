"""The detectors of one camera frame and one target: the image's gradient computed once, the model's
view of the target rendered in its box (at half resolution: it only says which edges show) and, for
each feature, a 2 x 2 supersampled view of its neighbourhood that its detector measures the image
against (:mod:`calib_core.look.corner_against_model`,
:func:`~calib_core.look.feature_detectors.detect_circle_against_model`)."""

from __future__ import annotations

import cv2
import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.scene import SceneItem
from calib_core.look.corner_against_model import detect_corner_against_model
from calib_core.look.edge_alignment import crease_segments
from calib_core.look.edge_samples import model_shows_edge
from calib_core.look.colour_contrast import gradient_magnitude
from calib_core.look.image_evidence import ImageEvidence
from calib_core.look.feature_detectors import (
    Detection,
    NotDetected,
    detect_blob,
    detect_circle,
    detect_circle_against_model,
    detect_corner,
    detect_corner_from_edges,
)
from calib_core.workcell.feature_kinds import FeatureKind

_BOX_MARGIN_PX = 24.0  # the widest search from an edge (8 px) and the corner's arms' windows, twice
_COARSE = 0.5  # the view that says which edges show, at half resolution
_DETAIL_SAMPLES = 2  # the test bed's camera integrates 2 x 2 (a real one its whole pixel area)
_DETAIL_MARGIN_PX = 12.0  # a detector's search (3 px), its profile's half (3 px) and the gradient's reach


def rim_points_mm(point: np.ndarray, kind: FeatureKind, count: int = 48) -> np.ndarray:
    """``count`` points (count, 3) mm evenly round the rim of a circle feature centred at ``point``
    (3,) mm, in the component's frame."""
    n = np.asarray(kind.normal)
    a = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    angles = np.linspace(0, 2 * np.pi, count, endpoint=False)
    return point + kind.radius_mm * (np.cos(angles)[:, None] * a + np.sin(angles)[:, None] * b)


def circle_rim(
    point: np.ndarray, kind: FeatureKind, obj2cam: np.ndarray, intrinsics: Intrinsics
) -> tuple[np.ndarray, np.ndarray]:
    """The projected rim (48, 2) of a circle feature and the perspective offset (2,)."""
    rim = project_points(rim_points_mm(point, kind), obj2cam, intrinsics)
    (cx, cy), _, _ = cv2.fitEllipse(rim.astype(np.float32))
    centre = project_points(point[None], obj2cam, intrinsics)[0]
    return rim, centre - (cx, cy)


class TargetDetectors:
    """The detectors of one image and one target: the gradient computed once, the edges that end at
    each corner found once.

    Its public members are what its detectors share of one image and one model view (the grey image and its gradient,
    the rendered expectation and its gradient, the model's segments and normals, the box corners) and ``detect``."""

    def __init__(self, evidence: ImageEvidence, item: SceneItem, intrinsics: Intrinsics, expected=None):
        self.grey = evidence.grey
        self.expected = expected
        self._rendered: tuple[np.ndarray, np.ndarray, np.ndarray] | None = (
            None  # (obj2cam, the view as rendered, its grey)
        )
        self._expected_magnitude: np.ndarray | None = None
        self._box = (0, 0, 0, 0)
        # edges from colour as well as lightness: an orange top on a tan table
        self.magnitude = evidence.magnitude
        self.intrinsics = intrinsics
        self.segments, self.normals = crease_segments(item.mesh)
        self.box_corners = trimesh.bounds.corners(item.mesh.bounds)

    def arms(self, point: np.ndarray, obj2cam: np.ndarray) -> list[np.ndarray]:
        """The far ends (3,) of the visible crease edges that end at ``point``."""
        if len(self.segments) == 0:
            return []
        centre = -obj2cam[:3, :3].T @ obj2cam[:3, 3]
        ends = []
        for k in range(2):
            near = np.linalg.norm(self.segments[:, k] - point, axis=1) < 0.5
            for e in np.flatnonzero(near):
                if (self.normals[e] @ (centre - point) > 0).any():
                    ends.append(self.segments[e, 1 - k])
        return ends

    def expected_image(self, obj2cam: np.ndarray) -> np.ndarray:
        """The model's view (h, w) grey with the target at ``obj2cam``: only the target's box and
        :data:`_BOX_MARGIN_PX` round it rendered (every search stays within the target's edges and a
        window of theirs), black elsewhere."""
        if self._rendered is None or not np.array_equal(self._rendered[0], obj2cam):
            corners = project_points(self.box_corners, obj2cam, self.intrinsics)
            lo, hi = np.floor(corners.min(axis=0)) - _BOX_MARGIN_PX, np.ceil(corners.max(axis=0)) + _BOX_MARGIN_PX
            h, w = self.grey.shape
            self._box = (max(int(lo[0]), 0), max(int(lo[1]), 0), min(int(hi[0]) + 1, w), min(int(hi[1]) + 1, h))
            view = self.expected(obj2cam, box_px=self._box, supersample=_COARSE)
            self._rendered = (obj2cam.copy(), view, ImageEvidence(view).grey)
            self._expected_magnitude = None
        return self._rendered[2]

    def expected_magnitude(self, obj2cam: np.ndarray) -> np.ndarray:
        """The gradient magnitude (h, w) of the model's view at ``obj2cam``, computed once per render and
        only in the rendered box (zero elsewhere)."""
        image = self.expected_image(obj2cam)
        if self._expected_magnitude is None:
            u0, v0, u1, v1 = self._box
            view = self._rendered[1]  # in the cell's colours: a colour-only edge shows there too
            self._expected_magnitude = np.zeros(image.shape, dtype=np.float32)
            if u1 > u0 and v1 > v0:
                self._expected_magnitude[v0:v1, u0:u1] = gradient_magnitude(view[v0:v1, u0:u1])
        return self._expected_magnitude

    def detail_magnitude(self, obj2cam: np.ndarray, points_px: np.ndarray) -> np.ndarray:
        """The gradient magnitude (h, w) of the model's view at ``obj2cam``, supersampled
        (:data:`_DETAIL_SAMPLES`) in the box round ``points_px`` (m, 2) and :data:`_DETAIL_MARGIN_PX`,
        zero elsewhere: what a feature's detector measures the image against (a camera's pixels
        integrate over their area; the plain view's edges are staircases)."""
        lo = np.floor(points_px.min(axis=0) - _DETAIL_MARGIN_PX).astype(int)
        hi = np.ceil(points_px.max(axis=0) + _DETAIL_MARGIN_PX).astype(int) + 1
        h, w = self.grey.shape
        u0, v0, u1, v1 = max(lo[0], 0), max(lo[1], 0), min(hi[0], w), min(hi[1], h)
        out = np.zeros((h, w), dtype=np.float32)
        if u1 > u0 and v1 > v0:
            image = self.expected(obj2cam, box_px=(u0, v0, u1, v1), supersample=_DETAIL_SAMPLES)
            out[v0:v1, u0:u1] = gradient_magnitude(image[v0:v1, u0:u1])
        return out

    def rendered_pose(self) -> np.ndarray | None:
        """The pose (4, 4) of the last model's view rendered."""
        return None if self._rendered is None else self._rendered[0]

    def _visible_arm(self, corner: np.ndarray, far: np.ndarray, magnitude: np.ndarray) -> np.ndarray | None:
        """The pixel (2,) the arm from ``corner`` to ``far`` (px) may be searched to, by the model's view
        (``magnitude``: its gradient, supersampled round the corner: at half resolution a faint edge's
        gradient falls under the threshold and the arm was lost): ``far`` when it shows an edge along most of the arm's
        first 40 px; the end of the
        stretch it shows from the corner when something stands in front of the rest (a gripper's finger
        across a plate's edge: the first 12 px or more are enough for a line); ``None`` when no edge shows."""
        d = far - corner
        length = float(np.linalg.norm(d))
        if length < 8.0:
            return None
        s = np.arange(4.0, min(0.8 * length, 40.0), 2.0)
        if len(s) < 2:
            return None
        shows = model_shows_edge(magnitude, corner + s[:, None] * d / length)
        if shows.mean() >= 0.6:
            return far
        run = int(np.argmin(shows)) if not shows.all() else len(shows)
        if run >= 5:  # shown from 4 px to 12 px or more: the search stops where it stops showing
            return corner + (s[run - 1] / 0.8) * d / length
        return None

    def _corner_from_lines(
        self, uv: np.ndarray, far: np.ndarray, radius: float, detail: np.ndarray, why: NotDetected
    ) -> Detection | NotDetected:
        """When fewer than two arms can be measured against the model's view (a finger beside an edge,
        shaded otherwise in the model: the Panda's plate corner), the lines the image shows along the
        arms, intersected, less where the model's own lines meet off the corner (``detail``: the
        model's supersampled gradient there); ``why`` when that fails too."""
        lines = detect_corner_from_edges(
            self.grey, uv, list(far), search_px=radius, magnitude=self.magnitude, lens=self.intrinsics
        )
        if not isinstance(lines, Detection):
            return why
        modelled = detect_corner_from_edges(
            self.grey, uv, list(far), search_px=radius, magnitude=detail, lens=self.intrinsics
        )
        if isinstance(modelled, Detection):
            weaker = lines if lines.confidence <= modelled.confidence else modelled
            return Detection(lines.uv_px - (modelled.uv_px - uv), weaker.confidence, weaker.why)
        return lines

    def detect(self, kind: FeatureKind, point, obj2cam, radius) -> Detection | NotDetected:
        """``point`` (3,) mm of the kind ``kind``, within ``radius`` px of its projection at ``obj2cam``."""
        uv = project_points(point[None], obj2cam, self.intrinsics)[0]
        if kind.kind == "corner":
            ends = self.arms(point, obj2cam)
            if ends:
                far = project_points(np.array(ends), obj2cam, self.intrinsics)
                if self.expected is not None:
                    # against the model's view, supersampled round the corner and along its arms' first 40 px:
                    # its chamfers, its plate's thickness and its silhouettes are the image's
                    reach = [
                        uv
                        + min(float(np.linalg.norm(f - uv)), 40.0) * (f - uv) / max(float(np.linalg.norm(f - uv)), 1e-9)
                        for f in far
                    ]
                    detail = self.detail_magnitude(obj2cam, np.vstack([uv[None], *[r[None] for r in reach]]))
                    # only the arms, or their stretches, along which the model shows an edge
                    shown = [self._visible_arm(uv, f, detail) for f in far]
                    far = np.array([f for f in shown if f is not None]).reshape(-1, 2)
                    found = detect_corner_against_model(
                        self.magnitude, detail, uv, list(far), search_px=max(radius, 1.5)
                    )
                    return (
                        found
                        if isinstance(found, Detection)
                        else self._corner_from_lines(uv, far, radius, detail, found)
                    )
                found = detect_corner_from_edges(
                    self.grey, uv, list(far), search_px=radius, magnitude=self.magnitude, lens=self.intrinsics
                )
                if isinstance(found, Detection):
                    return found
            return detect_corner(self.grey, uv, radius)
        if kind.kind == "circle":
            rim, offset = circle_rim(point, kind, obj2cam, self.intrinsics)
            if self.expected is not None:
                return detect_circle_against_model(
                    self.magnitude, self.detail_magnitude(obj2cam, rim), rim, uv, search_px=max(radius, 1.5)
                )
            return detect_circle(self.grey, rim, offset, search_px=radius, magnitude=self.magnitude)
        return detect_blob(self.grey, uv, max(radius, 6.0))
