"""A corner measured against the model's view: its edges' offsets from the model's, not the meeting of lines."""

import cv2
import numpy as np

from calib_core.look.corner_against_model import detect_corner_against_model
from calib_core.look.colour_contrast import gradient_magnitude
from calib_core.look.feature_detectors import Detection, NotDetected


def _plate(shift_px, size=120, samples=8) -> np.ndarray:
    """A dark plate on light grey, its corner at (60, 60) + ``shift_px`` chamfered by 3 px, and a
    lighter band 2 px wide along its top edge (the plate's front face seen at a grazing angle),
    anti-aliased (drawn ``samples`` times finer and box-filtered)."""
    big = np.full((size * samples, size * samples), 200, np.uint8)
    # the coarse pixel u covers the fine ones samples u .. samples u + samples - 1; vertices to 1/16 of a fine
    # pixel (the fill covers whole fine pixels: shifts in eighths of a pixel are drawn exactly)
    s = lambda pts: np.round(((np.asarray(pts, float) + shift_px) * samples + (samples - 1) / 2.0) * 16).astype(
        np.int32
    )  # noqa: E731
    plate = [(60.0, 63.0), (63.0, 60.0), (115.0, 60.0), (115.0, 115.0), (60.0, 115.0)]
    cv2.fillPoly(big, [s(plate)], 40, shift=4)
    cv2.fillPoly(big, [s([(63.0, 60.0), (115.0, 60.0), (115.0, 62.0), (63.0, 62.0)])], 90, shift=4)
    return cv2.resize(big, (size, size), interpolation=cv2.INTER_AREA)


def test_a_chamfered_corner_moves_with_the_image_by_the_known_shift():
    corner = np.array([60.0, 60.0])  # the virtual sharp corner the workcell names
    arms = [np.array([110.0, 60.0]), np.array([60.0, 110.0])]
    model = gradient_magnitude(_plate(np.zeros(2)))
    for shift in (np.array([0.375, -0.5]), np.array([-0.75, 0.25]), np.array([0.125, 0.625]), np.zeros(2)):
        image = gradient_magnitude(_plate(shift))
        found = detect_corner_against_model(image, model, corner, arms, search_px=2.0)
        assert isinstance(found, Detection)
        assert np.linalg.norm(found.uv_px - (corner + shift)) < 0.08, (
            shift,
            found.uv_px - corner,
        )  # the profile match's pixel locking: 0.04 a direction


def test_one_arm_is_not_enough_and_says_so():
    model = gradient_magnitude(_plate(np.zeros(2)))
    found = detect_corner_against_model(model, model, np.array([60.0, 60.0]), [np.array([110.0, 60.0])], search_px=2.0)
    assert isinstance(found, NotDetected) and "two of its edges" in found.reason
