"""Sub-pixel detectors for one feature each, searching a small window around where it should be.

Each returns a :class:`Detection` (pixel, confidence in [0, 1]) or a :class:`NotDetected` with the
reason an operator can act on. Pixels are (u, v) with (0, 0) the centre of the top-left pixel.

- corners: Harris corners in the window (``cv2.goodFeaturesToTrack``), the one nearest the prediction,
  refined by ``cv2.cornerSubPix``; when the refinement walks more than 1.5 px (three faces meeting),
  the Harris position is kept with a lower confidence;
- circles, with the model's view at the pose the edges found: along the rim's normals the image's
  gradient profile matched against the model's, the rim moved as a whole by the offsets
  (:func:`detect_circle_against_model`); without a model's view, the strongest gradient along the
  normals of the predicted ellipse (the projected circle, shifted), an ellipse fitted to those edge
  points, and its centre moved by the perspective offset (the image of the circle's centre minus the
  centre of the imaged ellipse, from the model);
- points: the centroid of the blob at the prediction, darker or brighter than its surroundings.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, undistort_pixels, unproject
from calib_core.look.profile_matching import match_profiles
from calib_core.look.colour_contrast import gradient_magnitude

_ALIKE = 0.5  # the least correlation of a rim point's gradient profile with the model's to measure it by


UNCERTAIN = 0.5
"""Below this confidence a detection says why it is unsure (the found-points table shows it)."""


@dataclass(frozen=True)
class Detection:
    """``uv_px`` (2,) px, ``confidence`` in [0, 1], ``why``: what lowered it, when below :data:`UNCERTAIN`."""

    uv_px: np.ndarray
    confidence: float
    why: str = ""


def detection(uv_px: np.ndarray, confidence: float, *causes: tuple[float, str]) -> Detection:
    """A detection whose ``why`` is the cause (factor, words) that lowered ``confidence`` most, when it is below
    :data:`UNCERTAIN`."""
    why = min(causes, key=lambda c: c[0])[1] if causes and confidence < UNCERTAIN else ""
    return Detection(uv_px, float(confidence), why)


@dataclass(frozen=True)
class NotDetected:
    reason: str


def _window(grey: np.ndarray, uv: np.ndarray, radius: int) -> tuple[np.ndarray, int, int] | None:
    h, w = grey.shape
    x0, y0 = int(round(uv[0])) - radius, int(round(uv[1])) - radius
    x1, y1 = x0 + 2 * radius + 1, y0 + 2 * radius + 1
    x0c, y0c, x1c, y1c = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    if x1c - x0c < 7 or y1c - y0c < 7:
        return None
    return grey[y0c:y1c, x0c:x1c], x0c, y0c


def detect_corner(grey: np.ndarray, uv_pred: np.ndarray, radius_px: float) -> Detection | NotDetected:
    """The corner nearest ``uv_pred`` within ``radius_px``."""
    win = _window(grey, uv_pred, int(np.ceil(radius_px)))
    if win is None:
        return NotDetected("at the edge of the image")
    roi, x0, y0 = win
    corners = cv2.goodFeaturesToTrack(
        roi, maxCorners=12, qualityLevel=0.05, minDistance=3, blockSize=5, useHarrisDetector=True, k=0.04
    )
    if corners is None:
        return NotDetected(f"no corner within {radius_px:.0f} px of where the model puts it")
    cand = corners.reshape(-1, 2) + (x0, y0)
    dist = np.linalg.norm(cand - uv_pred, axis=1)
    k = int(np.argmin(dist))
    if dist[k] > radius_px:
        return NotDetected(f"no corner within {radius_px:.0f} px of where the model puts it")
    start = cand[k].astype(np.float32).reshape(1, 1, 2).copy()
    refined = (
        cv2.cornerSubPix(grey, start, (4, 4), (-1, -1), (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 40, 0.01))
        .reshape(2)
        .astype(float)
    )
    confidence = 1.0
    # a second corner close by makes the choice uncertain
    others = np.sort(dist)[1:2]
    if len(others) and others[0] < 2.5:
        confidence *= 0.5
    crowded = (confidence, "another corner lies within 2.5 px")
    if np.linalg.norm(refined - cand[k]) > 1.5:  # the refinement walked off: three faces meet here
        return detection(
            cand[k].astype(float),
            0.3 * confidence,
            (0.3, "the sub-pixel refinement walked off it (three faces meeting?)"),
            crowded,
        )
    return detection(refined, confidence, crowded)


def search_normals(
    magnitude: np.ndarray, points: np.ndarray, normals: np.ndarray, search_px: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each point (m, 2) the strongest gradient along its unit normal (m, 2) within +-``search_px``:
    the edge points (m, 2) at sub-pixel precision (a parabola through the peak), their strengths (m,)
    and which searches stayed inside the image (m,) bool. One ``cv2.remap``
    for all searches (the moving-edges step of RAPID and ViSP's tracker)."""
    h, w = magnitude.shape
    steps = np.arange(-search_px, search_px + 0.25, 0.5)
    lines = points[:, None, :] + steps[None, :, None] * normals[:, None, :]  # (m, s, 2)
    inside = ((lines[..., 0] >= 1) & (lines[..., 0] < w - 2) & (lines[..., 1] >= 1) & (lines[..., 1] < h - 2)).all(
        axis=1
    )
    profile = cv2.remap(magnitude, lines[..., 0].astype(np.float32), lines[..., 1].astype(np.float32), cv2.INTER_LINEAR)
    k = np.argmax(profile, axis=1)
    rows = np.arange(len(points))
    kk = np.clip(k, 1, len(steps) - 2)
    a, b, c = profile[rows, kk - 1], profile[rows, kk], profile[rows, kk + 1]
    denom = a - 2 * b + c
    sub = np.where((denom < 0) & (k == kk), 0.5 * (a - c) / np.where(denom < 0, denom, -1.0), 0.0)
    offset = steps[0] + 0.5 * (k + sub)
    return points + offset[:, None] * normals, profile[rows, k], inside


def detect_circle(
    grey: np.ndarray,
    rim_px: np.ndarray,
    centre_offset_px: np.ndarray,
    search_px: float = 4.0,
    magnitude: np.ndarray | None = None,
    rim_has_contrast: np.ndarray | None = None,
) -> Detection | NotDetected:
    """The image of a circle's centre. ``rim_px`` (m, 2): the predicted rim (the projected circle,
    already shifted to where the target is); ``centre_offset_px`` (2,): the image of the centre minus the
    centre of the ellipse through the predicted rim (the perspective correction); ``rim_has_contrast``
    (m,) bool: where the model expects an edge on the rim (default: everywhere).

    With edge points on most of the rim an ellipse is fitted and its centre corrected for perspective;
    with a partial rim (a faint boss lit from one side) the predicted ellipse's shape is kept and only
    its position fitted to the edge points along their normals, which a short arc still determines."""
    mag = gradient_magnitude(grey) if magnitude is None else magnitude
    centre = rim_px.mean(axis=0)
    normals = rim_px - centre
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-9)
    points, strengths, inside = search_normals(mag, rim_px, normals, search_px)
    usable = inside if rim_has_contrast is None else inside & rim_has_contrast
    if usable.sum() < 6:
        return NotDetected("its rim is outside the image or has no contrast in the model's view")
    floor = max(8.0, 0.35 * float(np.median(strengths[usable])))
    strong = usable & (strengths >= floor)
    if strong.sum() < 6:
        return NotDetected(f"its rim has too little contrast ({int(strong.sum())} of {len(rim_px)} edge points)")
    coverage = strong.sum() / len(rim_px)
    if coverage >= 0.7:
        pts = points[strong].astype(np.float32)
        for _ in range(2):  # drop edge points off the ellipse (a shadow, a neighbouring edge) and refit
            ellipse = cv2.fitEllipse(pts)
            residual = _ellipse_residual(pts, ellipse)
            keep = residual < max(0.7, 2.5 * float(np.median(residual)))
            if keep.sum() < 8 or keep.all():
                break
            pts = pts[keep]
        ellipse = cv2.fitEllipse(pts)
        rms = float(np.sqrt(np.mean(_ellipse_residual(pts, ellipse) ** 2)))
        return detection(
            np.array(ellipse[0]) + centre_offset_px,
            float(np.clip(coverage, 0, 1) * np.exp(-rms / 0.7)),
            (float(coverage), f"only {100 * coverage:.0f} % of its rim found"),
            (float(np.exp(-rms / 0.7)), f"its rim is off an ellipse by {rms:.1f} px RMS"),
        )
    # a partial rim: the predicted ellipse moved as a whole onto the edge points (two unknowns)
    shift = _rim_shift(normals[strong], np.einsum("ij,ij->i", points[strong] - rim_px[strong], normals[strong]), 0.5)
    if isinstance(shift, NotDetected):
        return shift
    delta, rms, _ = shift
    predicted_centre = np.array(cv2.fitEllipse(rim_px.astype(np.float32))[0]) + centre_offset_px
    return detection(
        predicted_centre + delta,
        float(np.clip(coverage / 0.7, 0, 1) * 0.7 * np.exp(-rms / 0.5)),
        (float(coverage / 0.7 * 0.7), f"only {100 * coverage:.0f} % of its rim found: placed by the part seen"),
        (float(np.exp(-rms / 0.5)), f"its rim scatters by {rms:.1f} px"),
    )


def detect_circle_against_model(
    magnitude: np.ndarray,
    expected_magnitude: np.ndarray,
    rim_px: np.ndarray,
    centre_px: np.ndarray,
    search_px: float = 2.0,
) -> Detection | NotDetected:
    """The image of a circle's centre, measured against the model's view of it.

    ``rim_px`` (m, 2): the rim projected at the pose the edges found (a closed polygon, in order);
    ``centre_px`` (2,): the circle's centre projected at that pose (perspective included);
    ``magnitude`` and ``expected_magnitude`` (h, w): the gradient magnitude of the camera's image and of
    the model's view rendered at that pose. Along each rim point's normal the image's gradient profile
    is matched against the model's (:func:`~calib_core.look.profile_matching.match_profiles`): the
    offset is the image's edge less the model's, wherever the model's own edge lies (a boss's base
    circle or its side's outline within the window: an ellipse fitted to the image's edges alone came
    out 0.5-0.9 px off, outward, on every boss), and a side seen edge-on, a thin line with two peaks,
    is matched as the pair (the strongest of the two picked differently in image and model put a rim
    1-1.8 px off). The offsets move the rim as a whole (two unknowns, least squares on the normal
    offsets, outliers dropped), and the centre with it: the perspective is the model's, the place the
    image's. A point whose model edge lies more than 1.5 px from the rim, or whose profiles are
    unlike (correlation under 0.5), is left out (beside the gripper's fingers a boss came out up to
    2.5 px off)."""
    tangent = np.roll(rim_px, -1, axis=0) - np.roll(rim_px, 1, axis=0)
    normals = np.column_stack([-tangent[:, 1], tangent[:, 0]]) / np.maximum(
        np.linalg.norm(tangent, axis=1, keepdims=True), 1e-9
    )
    _, strength, inside = search_normals(magnitude, rim_px, normals, search_px)
    modelled, model_strength, _ = search_normals(expected_magnitude, rim_px, normals, 1.5)
    model_offset = np.einsum("ij,ij->i", modelled - rim_px, normals)
    offset, alike = match_profiles(magnitude, expected_magnitude, rim_px, normals, search_px)
    usable = inside & (model_strength >= 12.0) & (np.abs(model_offset) <= 1.5) & (alike >= _ALIKE)
    if usable.sum() < 6:
        return NotDetected(
            "its rim is outside the image, stands beside another edge in the model's view or looks unlike it "
            f"({int(usable.sum())} of {len(rim_px)} rim points clear)"
        )
    floor = max(8.0, 0.35 * float(np.median(strength[usable])))
    strong = usable & (strength >= floor)
    if strong.sum() < 6:
        return NotDetected(f"its rim has too little contrast ({int(strong.sum())} of {len(rim_px)} edge points)")
    shift = _rim_shift(normals[strong], offset[strong], 0.3)
    if isinstance(shift, NotDetected):
        return shift
    delta, rms, kept = shift
    return detection(
        centre_px + delta,
        float(np.clip(kept / len(rim_px) / 0.5, 0, 1) * np.exp(-rms / 0.5)),
        (
            float(kept / len(rim_px) / 0.5),
            f"only {100 * kept / len(rim_px):.0f} % of its rim measured against the model's",
        ),
        (float(np.exp(-rms / 0.5)), f"its rim scatters by {rms:.1f} px"),
    )


def _rim_shift(
    normals: np.ndarray, offsets_px: np.ndarray, floor_px: float
) -> tuple[np.ndarray, float, int] | NotDetected:
    """The shift (2,) px that moves rim points along their unit ``normals`` (m, 2) by ``offsets_px``
    (m,), least squares with points off by more than 3 robust sigmas (at least ``floor_px``) dropped
    twice at most; with its RMS residual and how many points it kept."""
    n, r = normals, offsets_px
    for _ in range(3):
        A = n.T @ n
        if np.linalg.eigvalsh(A)[0] < 0.05 * len(n):
            return NotDetected("too short an arc of its rim shows")
        delta = np.linalg.solve(A, n.T @ r)
        residual = r - n @ delta
        keep = np.abs(residual) < max(floor_px, 3.0 * 1.4826 * float(np.median(np.abs(residual))))
        if keep.all() or keep.sum() < 6:
            break
        n, r = n[keep], r[keep]
    return delta, float(np.sqrt(np.mean(residual**2))), len(n)


def detect_corner_from_edges(
    grey: np.ndarray,
    corner_px: np.ndarray,
    arms_px: list[np.ndarray],
    search_px: float = 3.0,
    magnitude: np.ndarray | None = None,
    lens: Intrinsics | None = None,
) -> Detection | NotDetected:
    """A corner as the meeting point of the image lines along the model's edges that end there.

    ``corner_px`` (2,): the predicted corner; ``arms_px``: for each edge ending at it, the predicted
    pixel of its other end. Edge points are searched along each arm's normal from 4 px out (clear of
    the junction, where three faces make ``cornerSubPix`` walk), a line fitted to each arm, and the
    point nearest every line taken. Needs two arms that are not parallel. With ``lens`` the lines are
    fitted where they are straight, in the ideal pinhole image, and the corner mapped back through the
    lens (a straight edge is curved in the image; with the test bed's k1 = -0.18 that moved the corners
    by a few hundredths of a pixel, more with a wider lens)."""
    mag = gradient_magnitude(grey) if magnitude is None else magnitude
    straight = (lambda uv: undistort_pixels(uv, lens)) if lens is not None and lens.has_distortion else (lambda uv: uv)
    lines = []
    for end in arms_px:
        d = end - corner_px
        length = float(np.linalg.norm(d))
        if length < 8.0:
            continue
        d /= length
        s = np.arange(4.0, min(0.8 * length, 40.0), 1.0)
        if len(s) < 4:
            continue
        normal = np.array([-d[1], d[0]])
        pts, strength, inside = search_normals(
            mag, corner_px + s[:, None] * d, np.repeat(normal[None], len(s), axis=0), search_px
        )
        good = inside & (strength >= max(10.0, 0.4 * float(np.median(strength[inside])) if inside.any() else 10.0))
        if good.sum() < 4:
            continue
        pts = straight(pts[good])
        for _ in range(2):
            centre = pts.mean(axis=0)
            _, _, vt = np.linalg.svd(pts - centre)
            n = vt[1]
            residual = np.abs((pts - centre) @ n)
            keep = residual < max(0.5, 3.0 * float(np.median(residual)))
            if keep.all() or keep.sum() < 4:
                break
            pts = pts[keep]
        lines.append((centre, n, float(np.sqrt(np.mean(residual**2))), len(pts)))
    if len(lines) < 2:
        return NotDetected("fewer than two of its edges are visible in the image")
    A = np.array([n for _, n, _, _ in lines])
    b = np.array([n @ c for c, n, _, _ in lines])
    if np.linalg.svd(A, compute_uv=False)[-1] < 0.25:  # the arms are nearly parallel
        return NotDetected("its edges are nearly parallel in the image")
    uv = np.linalg.lstsq(A, b, rcond=None)[0]
    if lens is not None and lens.has_distortion:
        uv = project(unproject(uv[None], lens, undistort=False), lens)[0]
    if np.linalg.norm(uv - corner_px) > search_px + 2.0:
        return NotDetected("its edges meet away from where they should")
    rms = max(r for _, _, r, _ in lines)
    return detection(uv, float(np.exp(-rms / 0.5)), (0.0, f"its edges are off straight lines by {rms:.1f} px RMS"))


def _ellipse_residual(points: np.ndarray, ellipse) -> np.ndarray:
    """Approximate distance (px) of each point from the ellipse (radial, in the ellipse's frame)."""
    (cx, cy), (a, b), angle = ellipse
    t = np.radians(angle)
    d = points - (cx, cy)
    x = d[:, 0] * np.cos(t) + d[:, 1] * np.sin(t)
    y = -d[:, 0] * np.sin(t) + d[:, 1] * np.cos(t)
    r = np.hypot(x / (a / 2), y / (b / 2))
    return np.abs(r - 1.0) * np.hypot(x, y) / np.maximum(r, 1e-9)


def detect_blob(grey: np.ndarray, uv_pred: np.ndarray, radius_px: float) -> Detection | NotDetected:
    """The centroid of the blob at ``uv_pred`` (Otsu's threshold in the window, the component nearest)."""
    win = _window(grey, uv_pred, int(np.ceil(radius_px)))
    if win is None:
        return NotDetected("at the edge of the image")
    roi, x0, y0 = win
    _, mask = cv2.threshold(roi, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    centre = np.array(roi.shape[::-1]) / 2
    inside = mask[
        int(min(max(uv_pred[1] - y0, 0), roi.shape[0] - 1)), int(min(max(uv_pred[0] - x0, 0), roi.shape[1] - 1))
    ]
    blob = (mask == inside).astype(np.uint8)
    n, labels, stats, centroids = cv2.connectedComponentsWithStats(blob)
    if n < 2:
        return NotDetected("no blob there")
    k = 1 + int(np.argmin(np.linalg.norm(centroids[1:] - centre, axis=1)))
    x, y, bw, bh, area = stats[k]
    if x == 0 or y == 0 or x + bw >= roi.shape[1] or y + bh >= roi.shape[0]:
        return NotDetected(f"no blob smaller than {2 * radius_px:.0f} px there")
    contrast = abs(float(roi[labels == k].mean()) - float(roi[labels != k].mean())) / 255.0
    return detection(
        centroids[k] + (x0, y0),
        float(np.clip(4 * contrast, 0, 1)),
        (0.0, f"a faint blob ({100 * contrast:.0f} % contrast)"),
    )
