"""A click on a corner moved to the corner: OpenCV's ``cornerSubPix`` round the click."""

from __future__ import annotations

import cv2
import numpy as np

from calib_core.look.image_evidence import ImageEvidence


def refine_corner_pick(
    image_rgb: np.ndarray | ImageEvidence, pixel, half_window: int = 5, max_shift_px: float = 2.0
) -> tuple[float, float]:
    """The corner nearest ``pixel`` (u, v) px to sub-pixel accuracy on ``image_rgb`` (h, w, 3) (or its evidence); the
    click itself when the refinement wanders further than ``max_shift_px`` (no corner there: a circle
    centre, a flat patch), since the operator's click is then the better estimate."""
    u, v = float(pixel[0]), float(pixel[1])
    grey = ImageEvidence.of(image_rgb).grey.astype(np.float32)
    corner = np.array([[[u, v]]], dtype=np.float32)
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 40, 0.01)
    try:
        refined = cv2.cornerSubPix(grey, corner, (half_window, half_window), (-1, -1), criteria)[0, 0]
    except cv2.error:  # a click too near the border for the search window
        return u, v
    if np.hypot(refined[0] - u, refined[1] - v) > max_shift_px:
        return u, v
    return float(refined[0]), float(refined[1])
