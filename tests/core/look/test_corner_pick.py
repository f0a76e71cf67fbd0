"""A click near a corner lands on it; a click on a flat patch stays where it was."""

import cv2
import numpy as np

from calib_core.look.corner_pick import refine_corner_pick


def _checker_corner(corner_uv, size=(64, 80), supersample=16) -> np.ndarray:
    """An RGB image (h, w, 3) of two dark and two light quadrants meeting at ``corner_uv`` px, area-sampled."""
    h, w = size
    s = supersample
    # pixel centres at integer coordinates: each fine pixel's centre in the coarse image's pixels
    v, u = np.mgrid[0 : h * s, 0 : w * s]
    u = (u + 0.5) / s - 0.5
    v = (v + 0.5) / s - 0.5
    light = (u > corner_uv[0]) ^ (v > corner_uv[1])
    big = np.where(light, 220, 30).astype(np.uint8)
    small = cv2.resize(big, (w, h), interpolation=cv2.INTER_AREA)
    return np.repeat(small[..., None], 3, axis=2)


def test_a_click_two_pixels_off_lands_on_the_corner():
    corner = (40.3, 30.7)
    image = _checker_corner(corner)
    u, v = refine_corner_pick(image, (41.5, 29.4))
    assert np.hypot(u - corner[0], v - corner[1]) < 0.15  # cornerSubPix: 0.11 px here, from 1.8 px away


def test_a_click_on_a_flat_patch_is_kept():
    image = np.full((64, 80, 3), 128, np.uint8)
    assert refine_corner_pick(image, (20.25, 30.5)) == (20.25, 30.5)


def test_a_click_at_the_border_is_kept():
    image = _checker_corner((40.3, 30.7))
    assert refine_corner_pick(image, (0.0, 0.0)) == (0.0, 0.0)
