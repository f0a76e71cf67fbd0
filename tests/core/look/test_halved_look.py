"""Find points on the image halved, for a part whose form error is more pixels than the edge fit's finest window: the
answer in the whole image's pixels, the model's view averaged as the photo is, and when it is done at all."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look.edge_refinement import FINEST_WINDOW_PX, EdgeFit
from calib_core.look.found_points import FoundPoints, Proposal
from calib_core.look.halved_look import at_full_size, halved_view, halvings
from calib_core.look.image_evidence import ImageEvidence


def _camera() -> Intrinsics:
    return Intrinsics(fu=1120.0, fv=1118.0, cx=641.3, cy=478.6, width=1280, height=960)


def _pose() -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = [4.0, -7.0, 180.0]
    return pose


def test_a_point_found_on_the_halved_image_is_given_where_the_whole_camera_sees_it():
    rng = np.random.default_rng(3)
    points = rng.uniform(-40.0, 40.0, (6, 3))
    camera = _camera()
    on_half = project_points(points, _pose(), camera.scaled(0.5))
    found = FoundPoints(
        "part",
        True,
        "6 of 6 features of part found",
        tuple(Proposal(f"f{i}", "corner", uv, p, 0.9, 0.25) for i, (uv, p) in enumerate(zip(on_half, points))),
        offset_px=np.array([1.5, -2.0]),
    )
    whole = at_full_size(found, 1, "its bend is 3.3 px")
    np.testing.assert_allclose(
        np.array([p.uv_px for p in whole.proposals]), project_points(points, _pose(), camera), atol=1e-9
    )
    assert [p.residual_px for p in whole.proposals] == [0.5] * 6  # a length: doubled, not moved
    np.testing.assert_allclose(whole.offset_px, [3.0, -4.0])
    assert whole.message == (
        "6 of 6 features of part found (looked at the image at half its size, where the figures above are measured: "
        "its bend is 3.3 px)"
    )
    on_quarter = project_points(points, _pose(), camera.scaled(0.5).scaled(0.5))
    quarter = replace(found, proposals=tuple(replace(p, uv_px=uv) for p, uv in zip(found.proposals, on_quarter)))
    np.testing.assert_allclose(
        np.array([p.uv_px for p in at_full_size(quarter, 2, "").proposals]),
        project_points(points, _pose(), camera),
        atol=1e-9,
    )


def test_an_edge_fit_on_the_halved_image_keeps_its_verdict_in_the_whole_images_pixels():
    # settled within 0.5 px of the halved image with 60 % of its samples: 0.8 px of the whole image's, still settled
    fit = EdgeFit(
        _pose(),
        0.4,
        0.35,
        80,
        np.eye(6),
        True,
        np.array([[10.0, 20.0]]),
        np.array([0.3]),
        np.array([[0.3, 0.0]]),
        0.62,
        min_share=0.6,
    )
    assert fit.settled
    whole = at_full_size(FoundPoints("part", True, "found", edges=fit), 1, "why").edges
    assert whole.settled and whole.rms_px == 0.8 and whole.sigma_px == 0.7 and whole.rms_bound_px == 1.0
    np.testing.assert_allclose(whole.edges_px, [[20.5, 40.5]])
    np.testing.assert_allclose(whole.residuals_px, [[0.6, 0.0]])
    assert not at_full_size(FoundPoints("part", True, "found", edges=replace(fit, rms_px=0.6)), 1, "why").edges.settled


def test_the_model_s_view_for_the_halved_image_is_the_whole_view_averaged_as_the_photo_is():
    asked = []

    def expected(obj2cam, box_px=None, supersample=1):
        # a view rendered only in its box: a gradient across it, black elsewhere
        asked.append((box_px, supersample))
        image = np.zeros((960, 1280, 3), np.uint8)
        u0, v0, u1, v1 = box_px
        image[v0:v1, u0:u1] = (np.arange(u0, u1)[None, :, None] % 200 + 50).astype(np.uint8)
        return image

    view = halved_view(expected, 1)(_pose(), box_px=(100, 50, 161, 90), supersample=2)
    assert asked == [((200, 100, 322, 180), 2)]
    assert view.shape == (480, 640, 3)
    np.testing.assert_array_equal(view, ImageEvidence(expected(_pose(), box_px=(200, 100, 322, 180))).half().image)
    shown = np.argwhere(view[..., 0] > 0)
    assert shown.min(axis=0).tolist() == [50, 100] and shown.max(axis=0).tolist() == [89, 160]
    assert halved_view(None, 1) is None
    odd = halved_view(lambda pose, box_px=None, supersample=1: np.full((961, 1281, 3), 80, np.uint8), 1)(_pose())
    assert odd.shape == (480, 640, 3)  # the last row and column left out, as the photo's half leaves them
    quarter = halved_view(expected, 2)(_pose(), box_px=(50, 25, 80, 45))
    assert asked[-1] == ((200, 100, 320, 180), 1) and quarter.shape == (240, 320, 3)
    np.testing.assert_array_equal(
        quarter, ImageEvidence(expected(_pose(), box_px=(200, 100, 320, 180))).half().half().image
    )


def test_an_image_is_halved_until_the_bend_is_within_the_finest_window_while_it_stays_wide_enough():
    assert halvings(3.3, 1280) == 1  # the workshop fixture close up at full size: 1.65 px halved
    assert halvings(1.6, 1280) == 0  # from its approach, 350 mm away: the fit averages it in place
    assert halvings(FINEST_WINDOW_PX, 1280) == 0
    assert halvings(7.0, 1280) == 2  # 3.5 px halved, 1.75 a quarter
    assert halvings(30.0, 1280) == 2  # no narrower than 320 px: as near the window as the image allows
    assert halvings(3.3, 600) == 0  # halved, 300 px: too few pixels for the features' detectors
    assert halvings(3.3, 640) == 1
