"""An edge's place in the image measured against the model's view of it, by the whole profile across it.

The strongest gradient along a normal is the edge only when the edge has one: a boss's side seen
at a grazing angle is a thin line, two gradient peaks 2 px apart of about equal strength, and the
camera's lighting and the model's pick different ones (a rim came out 1-1.8 px off). Matching the
gradient profile across the edge, image against model, aligns the two peaks together: the shift that
maximises their normalised correlation is the edge's offset from where the model draws it.
"""

from __future__ import annotations

import cv2
import numpy as np

_STEP_PX = 0.5


def _profiles(magnitude: np.ndarray, points: np.ndarray, normals: np.ndarray, half_px: float) -> np.ndarray:
    """The gradient magnitude (m, s) sampled every half pixel from -``half_px`` to +``half_px`` along
    each point's (m, 2) unit normal (m, 2)."""
    steps = np.arange(-half_px, half_px + 1e-9, _STEP_PX)
    lines = points[:, None, :] + steps[None, :, None] * normals[:, None, :]
    return cv2.remap(magnitude, lines[..., 0].astype(np.float32), lines[..., 1].astype(np.float32), cv2.INTER_LINEAR)


def match_profiles(
    magnitude: np.ndarray,
    expected_magnitude: np.ndarray,
    points_px: np.ndarray,
    normals: np.ndarray,
    search_px: float,
    half_px: float = 3.0,
) -> tuple[np.ndarray, np.ndarray]:
    """How far (m,) px along each unit normal (m, 2) the image's edge lies from the model's at the
    points (m, 2) px, and how alike the two profiles are there (m,) in [-1, 1].

    ``magnitude`` and ``expected_magnitude`` (h, w): the gradient magnitudes of the camera's image
    and of the model's view. The model's profile over +-``half_px`` is slid over the image's within
    +-``search_px``; the shift of the best normalised correlation, refined by a parabola through its
    neighbours, is the offset (positive along the normal). A flat profile, and a best match at the
    search's end (the edge may lie beyond it), have a correlation of 0."""
    model = _profiles(expected_magnitude, points_px, normals, half_px)  # (m, w)
    image = _profiles(magnitude, points_px, normals, half_px + search_px)  # (m, w + 2 k)
    width = model.shape[1]
    shifts = image.shape[1] - width + 1
    windows = np.lib.stride_tricks.sliding_window_view(image, width, axis=1)  # (m, shifts, w)
    a = model - model.mean(axis=1, keepdims=True)
    b = windows - windows.mean(axis=2, keepdims=True)
    norm = np.linalg.norm(a, axis=1)[:, None] * np.linalg.norm(b, axis=2)
    correlation = np.where(norm > 1e-6, np.einsum("mw,msw->ms", a, b) / np.maximum(norm, 1e-6), 0.0)
    k = np.argmax(correlation, axis=1)
    rows = np.arange(len(points_px))
    kk = np.clip(k, 1, shifts - 2)
    left, mid, right = correlation[rows, kk - 1], correlation[rows, kk], correlation[rows, kk + 1]
    denom = left - 2 * mid + right
    sub = np.where((k == kk) & (denom < 0), 0.5 * (left - right) / np.where(denom < 0, denom, -1.0), 0.0)
    offset = (k + sub) * _STEP_PX - search_px
    # a best match at the search's end may lie beyond it: not measured
    return offset, np.where((k > 0) & (k < shifts - 1), correlation[rows, k], 0.0)
