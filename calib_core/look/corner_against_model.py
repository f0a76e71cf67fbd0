"""A corner measured against the model's view of it: how far its edges lie from where the model draws them.

A corner's image is not where its edges' lines meet when the corner is chamfered, when the plate's
front and back top edges run 2-3 px apart at a grazing angle, or when one edge is a silhouette and the
other a crease: lines fitted to the image alone put the test bed's plate corners 0.4-0.9 px off at the
task location (the edges' fit put them within 0.03 px). The model's view has the same chamfer, the
same thickness and the same silhouette; measuring the image's edges against the model's, profile
against profile (:func:`~calib_core.look.profile_matching.match_profiles`), leaves only the corner's
displacement.
"""

from __future__ import annotations

import numpy as np

from calib_core.look.feature_detectors import Detection, NotDetected, detection, search_normals
from calib_core.look.profile_matching import match_profiles

_FROM_CORNER_PX = 4.0  # clear of the junction, where three faces meet
_ARM_PX = 40.0
_MIN_POINTS = 4
_ALIKE = 0.5
_MODEL_EDGE_PX = 1.5


def detect_corner_against_model(
    magnitude: np.ndarray,
    expected_magnitude: np.ndarray,
    corner_px: np.ndarray,
    arms_px: list[np.ndarray],
    search_px: float = 2.0,
) -> Detection | NotDetected:
    """The image of a corner from its edges' offsets against the model's view.

    ``corner_px`` (2,): the corner projected at the pose the model's view was rendered at; ``arms_px``:
    for each edge that ends there and that the model shows, the pixel (2,) it is searched to;
    ``magnitude``, ``expected_magnitude`` (h, w): the gradient magnitudes of the image and of the
    model's view. Every pixel along each arm from 4 px out (up to 40 px), the image's profile across
    the arm is matched with the model's: offset ``o = n . delta + w s``, with ``delta`` (2,) px the
    corner's displacement, ``w`` the arm's small turn and ``s`` the distance along it. Least squares
    over the arms (two, not parallel, at least), points off by more than 3 robust sigmas dropped.
    The corner is ``corner_px + delta``."""
    rows, offsets, arms_used = [], [], 0
    arms = [np.asarray(a, dtype=float) for a in arms_px]
    for k, end in enumerate(arms):
        d = end - corner_px
        length = float(np.linalg.norm(d))
        if length < 2 * _FROM_CORNER_PX:
            continue
        d /= length
        s = np.arange(_FROM_CORNER_PX, min(length, _ARM_PX), 1.0)
        normal = np.array([-d[1], d[0]])
        points = corner_px + s[:, None] * d
        normals = np.repeat(normal[None], len(s), axis=0)
        modelled, model_strength, inside = search_normals(expected_magnitude, points, normals, _MODEL_EDGE_PX)
        offset, alike = match_profiles(magnitude, expected_magnitude, points, normals, search_px)
        usable = inside & (model_strength >= 12.0) & (alike >= _ALIKE)
        if usable.sum() < _MIN_POINTS:
            continue
        arms_used += 1
        for si, oi in zip(s[usable], offset[usable]):
            row = np.zeros(2 + len(arms))
            row[:2] = normal
            row[2 + k] = si
            rows.append(row)
            offsets.append(oi)
    if arms_used < 2:
        return NotDetected("fewer than two of its edges show in both the image and the model's view")
    A, o = np.array(rows), np.array(offsets)
    A = A[:, np.r_[0, 1, 2 + np.flatnonzero(np.abs(A[:, 2:]).sum(axis=0) > 0)]]
    normals = A[:, :2]
    if np.linalg.svd(normals / np.sqrt(len(normals)), compute_uv=False)[-1] < 0.2:
        return NotDetected("its edges are nearly parallel in the image")
    keep = np.ones(len(o), dtype=bool)
    for _ in range(3):
        x = np.linalg.lstsq(A[keep], o[keep], rcond=None)[0]
        residual = o - A @ x
        limit = max(0.3, 3.0 * 1.4826 * float(np.median(np.abs(residual[keep]))))
        now = np.abs(residual) < limit
        if (now == keep).all() or now.sum() < 2 * _MIN_POINTS:
            break
        keep = now
    delta = x[:2]
    if np.linalg.norm(delta) > search_px:
        return NotDetected("its edges lie away from where the model's view draws them")
    rms = float(np.sqrt(np.mean(residual[keep] ** 2)))
    return detection(
        corner_px + delta,
        float(np.clip(keep.mean(), 0.0, 1.0) * np.exp(-rms / 0.5)),
        (float(keep.mean()), f"only {100 * keep.mean():.0f} % of its edges' samples agree with the model's view"),
        (float(np.exp(-rms / 0.5)), f"its edges differ from the model's view by {rms:.1f} px RMS"),
    )
