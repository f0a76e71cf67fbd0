"""One image's evidence: each product computed once and equal to what it stands for, the half-size level where the
scaled camera puts its points, and a look whose starts share one Canny pass."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look import colour_contrast
from calib_core.look.image_evidence import ImageEvidence


def _photo(seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    image = np.full((120, 160, 3), (90, 110, 70), np.uint8)
    cv2.rectangle(image, (40, 30), (110, 90), (200, 120, 40), -1)
    return np.clip(image + rng.normal(0, 3, image.shape), 0, 255).astype(np.uint8)


def test_each_product_is_what_it_stands_for_and_is_computed_once():
    image = _photo()
    evidence = ImageEvidence(image)
    assert np.array_equal(evidence.grey, cv2.cvtColor(image, cv2.COLOR_RGB2GRAY))
    # (OpenCV's filters differ in the last float bit from run to run)
    assert np.allclose(evidence.magnitude, colour_contrast.gradient_magnitude(image), atol=1e-4)
    assert np.allclose(evidence.grey_magnitude, colour_contrast.gradient_magnitude(evidence.grey), atol=1e-4)
    assert np.array_equal(evidence.edges, colour_contrast.edges(image))
    untruncated = cv2.distanceTransform((colour_contrast.edges(image) == 0).astype(np.uint8), cv2.DIST_L2, 3)
    assert np.array_equal(evidence.edge_distance(8.0), np.minimum(untruncated, 8.0))
    assert evidence.edge_distance(8.0).max() == 8.0 and evidence.edge_distance(40.0).max() > 8.0
    # asked again: the same arrays, not new ones
    assert evidence.grey is evidence.grey and evidence.magnitude is evidence.magnitude
    assert evidence.edge_distance(8.0) is evidence.edge_distance(8) and evidence.half() is evidence.half()
    assert ImageEvidence.of(evidence) is evidence and evidence.source is image


def test_a_grey_image_is_its_own_grey_and_has_no_colours():
    grey = cv2.cvtColor(_photo(), cv2.COLOR_RGB2GRAY)
    evidence = ImageEvidence(grey)
    assert evidence.grey is evidence.image and evidence.colour is None and evidence.colour_bins is None
    assert evidence.grey_magnitude is evidence.magnitude


def test_the_colour_bins_are_the_region_models():
    image = _photo()
    bins = ImageEvidence(image).colour_bins
    q = image.astype(np.int32) // 8  # 32 levels a channel
    assert np.array_equal(bins, (q[..., 0] * 32 + q[..., 1]) * 32 + q[..., 2])


def test_the_half_size_level_puts_a_point_where_the_scaled_camera_does():
    """A bright dot at a known pixel of a 640 x 480 image lies, at half size, where ``intrinsics.scaled(0.5)``
    projects the same 3D point (to a tenth of a pixel: the pyramid's Gaussian is symmetric)."""
    intrinsics = Intrinsics(fu=600.0, fv=600.0, cx=319.5, cy=239.5, width=640, height=480)
    point = np.array([[31.0, -17.0, 500.0]])
    uv = project_points(point, np.eye(4), intrinsics)[0]
    image = np.zeros((480, 640), np.uint8)
    cv2.circle(image, tuple(int(round(c)) for c in uv), 6, 255, -1)
    moments = cv2.moments(ImageEvidence(image).half().image.astype(np.float32))
    found = np.array([moments["m10"], moments["m01"]]) / moments["m00"]
    drawn = cv2.moments(image.astype(np.float32))
    drawn_uv = np.array([drawn["m10"], drawn["m01"]]) / drawn["m00"]
    expected = project_points(point, np.eye(4), intrinsics.scaled(0.5))[0] + (drawn_uv - uv) / 2.0
    assert ImageEvidence(image).half().shape == (240, 320)
    assert np.linalg.norm(found - expected) < 0.1


@pytest.mark.parametrize(
    "image, words",
    [(np.zeros((4, 4), np.float32), "uint8"), (np.zeros((4, 4, 2), np.uint8), "(4, 4, 2)")],
)
def test_an_image_that_is_none_is_named(image, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
        ImageEvidence(image)


def test_the_coarse_fit_s_pyramid_halves_a_large_photo_twice_and_a_small_one_once():
    """Known answers: a 1920 x 1440 photo's levels are 480 and 960 px wide (smallest first), a 640 x 480 one's 320, a
    500 px one's 250 (at least one level); each level's camera is the scaled one whose image it is."""
    from calib_core.camera.intrinsics import Intrinsics
    from calib_core.look.coarse_to_fine import pyramid
    from calib_core.look.image_evidence import ImageEvidence

    for size, widths in (((1920, 1440), [480, 960]), ((640, 480), [320]), ((500, 300), [250])):
        w, h = size
        camera = Intrinsics(1.2 * w, 1.2 * w, (w - 1) / 2.0, (h - 1) / 2.0, w, h)
        levels = pyramid(ImageEvidence(np.zeros((h, w, 3), np.uint8)), camera)
        assert [level.shape[1] for level, _ in levels] == widths
        for level, scaled in levels:
            assert (scaled.width, scaled.height) == (level.shape[1], level.shape[0])
            assert scaled.fu == pytest.approx(1.2 * w * level.shape[1] / w)
            assert scaled.cx == pytest.approx((level.shape[1] - 1) / 2.0)


def test_the_half_of_an_odd_sized_image_comes_with_a_camera_of_its_own_size():
    camera = Intrinsics(fu=1000.0, fv=1000.0, cx=640.0, cy=480.0, width=1283, height=963)
    half, half_camera = ImageEvidence(np.zeros((963, 1283, 3), np.uint8)).half_with(camera)
    assert half.shape[:2] == (481, 641)
    assert (camera.scaled(0.5).width, camera.scaled(0.5).height) == (642, 482)  # scaling the size rounds 641.5 up
    assert (half_camera.width, half_camera.height) == (641, 481)
    assert half_camera.fu == 500.0 and half_camera.cx == camera.scaled(0.5).cx
