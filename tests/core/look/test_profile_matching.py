"""An edge's offset from the model's by the whole gradient profile across it."""

import numpy as np

from calib_core.look.colour_contrast import gradient_magnitude
from calib_core.look.feature_detectors import search_normals
from calib_core.look.profile_matching import match_profiles


def _step(u: np.ndarray, at_px: float) -> np.ndarray:
    """An anti-aliased step (0 to 1) at ``at_px``."""
    return np.clip(u - at_px + 0.5, 0.0, 1.0)


def _thin_line(shift_px: float, down: float, up: float, size: int = 80) -> np.ndarray:
    """A dark line 2 px wide from column 39.5 + ``shift_px``: the grey steps ``down`` into it and
    ``up`` out of it (a boss's side seen edge-on, lit one way or the other): two gradient peaks 2 px
    apart, the stronger one where the larger step is."""
    u = np.arange(size, dtype=float)
    row = 140.0 - down * _step(u, 39.5 + shift_px) + up * _step(u, 41.5 + shift_px)
    return np.tile(row, (size, 1)).astype(np.uint8)


def test_a_thin_line_s_offset_is_measured_where_the_strongest_peak_is_not():
    """The model's line and the image's 0.8 px apart, lit differently: the model's stronger peak is
    its left side, the image's its right. The strongest-peak search is off by about the line's
    width; the profile match finds the 0.8 px."""
    model = gradient_magnitude(_thin_line(0.0, 60.0, 48.0))
    image = gradient_magnitude(_thin_line(0.8, 50.0, 58.0))
    points = np.column_stack([np.full(20, 40.5), np.arange(30.0, 50.0)])
    normals = np.tile([1.0, 0.0], (20, 1))
    offset, alike = match_profiles(image, model, points, normals, search_px=2.0)
    assert np.allclose(offset, 0.8, atol=0.15), offset
    assert (alike > 0.6).all()  # above the detectors' 0.5: used
    found, _, _ = search_normals(image, points, normals, 2.5)
    modelled, _, _ = search_normals(model, points, normals, 2.5)
    assert abs(np.median(found[:, 0] - modelled[:, 0]) - 0.8) > 1.0  # the strongest peaks: the other side


def test_offsets_round_trip_a_known_shift_of_a_step_edge_both_ways():
    for shift in (-1.3, -0.4, 0.0, 0.6, 1.7):
        model = gradient_magnitude(
            np.tile(100.0 + 80.0 * _step(np.arange(80, dtype=float), 39.5), (80, 1)).astype(np.uint8)
        )
        step = 100.0 + 80.0 * _step(np.arange(80, dtype=float), 39.5 + shift)
        image = gradient_magnitude(np.tile(step, (80, 1)).astype(np.uint8))
        points = np.column_stack([np.full(10, 40.0), np.arange(35.0, 45.0)])
        offset, _ = match_profiles(image, model, points, np.tile([1.0, 0.0], (10, 1)), search_px=2.5)
        assert np.allclose(offset, shift, atol=0.08), (
            shift,
            offset,
        )  # a parabola through half-pixel samples (pixel locking): 0.04-0.07
        back, _ = match_profiles(model, image, points, np.tile([1.0, 0.0], (10, 1)), search_px=2.5)
        assert np.allclose(back, -shift, atol=0.08), (shift, back)


def test_an_edge_beyond_the_search_is_not_measured():
    model = gradient_magnitude(
        np.tile(100.0 + 80.0 * _step(np.arange(80, dtype=float), 39.5), (80, 1)).astype(np.uint8)
    )
    image = gradient_magnitude(
        np.tile(100.0 + 80.0 * _step(np.arange(80, dtype=float), 44.5), (80, 1)).astype(np.uint8)
    )
    _, alike = match_profiles(image, model, np.array([[40.0, 40.0]]), np.array([[1.0, 0.0]]), search_px=2.0)
    assert alike[0] == 0.0


def test_a_flat_profile_is_unlike_anything():
    flat = np.zeros((40, 40), dtype=np.float32)
    edge = gradient_magnitude(np.tile((np.arange(40) >= 20).astype(np.uint8) * 90, (40, 1)))
    _, alike = match_profiles(flat, edge, np.array([[20.0, 20.0]]), np.array([[1.0, 0.0]]), search_px=2.0)
    assert alike[0] == 0.0
