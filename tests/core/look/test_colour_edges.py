"""Find points sees what the eye sees: a target whose colour differs from what is behind it while its
grey level does not. The test bed's cell with the fixture painted orange and the unit behind it tan, of one grey
(OpenCV's luma 0.635 both), seen from the task location where the fixture's face fills the view: in grey its
outline is gone (the grey path: "its edges did not settle"); in colour every feature is found. The truth only
scores."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

from calib_core.look import colour_contrast
from calib_core.look.edge_alignment import edge_distance_map, edge_samples_px, matched_share
from calib_core.look.find_points import find_points
from calib_core.render.model_view import ModelView
from calib_core.robot import solve_ik
from calib_core.workcell import load_workcell
from tests.core.look.find_points_scenes import TARGET, errors_times, pixel_errors
from videocal_sim.test_bed import TestBed

ORANGE, TAN = (1.0, 0.55, 0.12), (0.74, 0.62, 0.44)  # 0.299 R + 0.587 G + 0.114 B: 0.6355 and 0.6354


def _luma(rgb) -> float:
    return 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2]


def _painted_look(target_rgb, behind_rgb):
    cell = load_workcell()
    paint = {TARGET: target_rgb, "oru_1": behind_rgb}
    cell = dataclasses.replace(
        cell, components=[dataclasses.replace(c, color=paint.get(c.name, c.color)) for c in cell.components]
    )
    bed = TestBed.create(workcell=cell, errors=errors_times(1.0))
    q = solve_ik(bed.model_robot, cell.task("oru_1_grasp").tcp2base, np.array(cell.home_joints_deg, float)).q_deg
    bed.joints_deg = q
    camera = bed.camera()
    image = camera.read().image
    item = cell.component(TARGET)
    model = np.linalg.inv(bed.model_cam2world(q)) @ item.item2world
    truth = np.linalg.inv(camera.last_truth.cam2world) @ item.item2world
    view = ModelView(bed.intrinsics)
    expected = view.of_cell(cell.components, bed.visuals_for_model(), q, item.item2world)
    try:
        yield image, bed.intrinsics, item, model, truth, expected
    finally:
        view.close()
        camera.close()


@pytest.fixture(scope="module")
def equal_grey():
    assert abs(_luma(ORANGE) - _luma(TAN)) < 1e-3
    yield from _painted_look(ORANGE, TAN)


def test_the_outline_is_an_edge_in_colour_and_not_in_grey(equal_grey):
    image, intrinsics, item, model, truth, _ = equal_grey
    outline = edge_samples_px(item.mesh, truth, intrinsics)
    grey = cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    in_grey = matched_share(outline, edge_distance_map(grey))
    in_colour = matched_share(outline, edge_distance_map(image))
    assert in_colour > 0.5 and in_grey < 0.3, (
        in_grey,
        in_colour,
    )  # 0.61 and 0.27: the hidden and inner edges never match
    # the colour gradient of a grey image is the grey gradient: nothing changes for a monochrome camera
    g = cv2.GaussianBlur(grey, (3, 3), 0.8).astype(np.float32)
    np.testing.assert_array_equal(
        colour_contrast.gradient_magnitude(grey),
        np.hypot(cv2.Sobel(g, cv2.CV_32F, 1, 0, ksize=3), cv2.Sobel(g, cv2.CV_32F, 0, 1, ksize=3)),
    )
    assert np.array_equal(colour_contrast.edges(grey), cv2.Canny(cv2.GaussianBlur(grey, (5, 5), 1.0), 20, 60))


def test_find_points_finds_a_target_whose_edges_are_colour_only(equal_grey):
    image, intrinsics, item, model, truth, expected = equal_grey
    found = find_points(image, intrinsics, item, model, expected=expected)
    assert found.found, found.message
    assert len(found.proposals) == len(item.features)
    assert pixel_errors(item, found.obj2cam, truth, intrinsics).max() < 0.5
    # the same frame in grey: the outline is gone and the fit does not settle (the report's "0 % of its edges")
    grey = find_points(cv2.cvtColor(image, cv2.COLOR_RGB2GRAY), intrinsics, item, model, expected=expected)
    assert not grey.found


def test_dark_on_dark_is_found_as_well():
    for image, intrinsics, item, model, truth, expected in _painted_look((0.16, 0.15, 0.17), (0.24, 0.23, 0.25)):
        found = find_points(image, intrinsics, item, model, expected=expected)
        assert found.found, found.message
        assert pixel_errors(item, found.obj2cam, truth, intrinsics).max() < 0.5


def test_an_unsure_detection_names_what_made_it_unsure():
    from calib_core.look.feature_detectors import UNCERTAIN, detection

    sure = detection(np.zeros(2), 0.8, (0.9, "rim partly found"), (0.89, "rim scatters"))
    assert sure.why == ""
    unsure = detection(np.zeros(2), 0.3, (0.9, "only 90 % of its rim found"), (0.33, "its rim scatters by 0.6 px"))
    assert unsure.confidence < UNCERTAIN and unsure.why == "its rim scatters by 0.6 px"
