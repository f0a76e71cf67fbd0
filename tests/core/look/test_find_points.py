"""Find points and the edge refinement on the test bed's simulated camera (its own lighting, lens,
noise and vignetting), from the pose the robot model gives: the truth only scores."""

from __future__ import annotations

import numpy as np
import pytest

from calib_core.camera.projection import project_points
from calib_core.look.colour_contrast import gradient_magnitude
from calib_core.look.edge_alignment import edge_distance_map
from calib_core.look.edge_refinement import refine_to_edges
from calib_core.look.edge_samples import edge_points
from calib_core.look.find_points import find_points
from calib_core.look.pose_hypotheses import TRUNCATE_PX, rank_starts
from calib_core.render.model_view import ModelView
from calib_core.robot import solve_ik
from tests.core.look.find_points_scenes import TARGET, errors_times, pixel_errors
from videocal_sim.sim_camera import CameraLook
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors


def _look(factor: float, place: str = "approach"):
    """The paper's task location's approach (or the ``task`` location itself, 177 mm from the fixture)
    seen through a robot with ``factor`` times the typical errors: (image, intrinsics, item, modelled
    obj2cam, true obj2cam, expected)."""
    bed = TestBed.create(errors=errors_times(factor))
    cell = bed.workcell
    task = cell.task("oru_1_grasp")
    q = solve_ik(
        bed.model_robot,
        task.approach2base if place == "approach" else task.tcp2base,
        np.array(cell.home_joints_deg, float),
    ).q_deg
    bed.joints_deg = q
    camera = bed.camera()
    frame = camera.read()
    item = cell.component(TARGET)
    obj2cam_model = np.linalg.inv(bed.model_cam2world(q)) @ item.item2world
    obj2cam_true = np.linalg.inv(camera.last_truth.cam2world) @ item.item2world
    view = ModelView(bed.intrinsics)
    expected = view.of_cell(cell.components, bed.visuals_for_model(), q, item.item2world)
    yield frame.image, bed.intrinsics, item, obj2cam_model, obj2cam_true, expected
    view.close()
    camera.close()


@pytest.fixture(scope="module", params=[1.0, 2.0], ids=["typical errors", "twice the typical errors"])
def look(request):
    yield from _look(request.param)


def test_the_edges_put_every_feature_within_a_fifth_of_a_pixel(look):
    image, intrinsics, item, model, truth, expected = look
    assert pixel_errors(item, model, truth, intrinsics).max() > 4.0  # the robot's error, before
    grey = image.mean(axis=2).astype(np.uint8)
    samples, _, _, _ = edge_points(
        item.mesh, model, intrinsics, gradient_magnitude(expected(model).mean(axis=2).astype(np.uint8))
    )
    start = rank_starts(edge_distance_map(grey, TRUNCATE_PX), intrinsics, samples, model, reach_mm=20.0, reach_deg=1.5)[
        0
    ]
    fit = refine_to_edges(
        grey,
        intrinsics,
        item.mesh,
        start,
        expected_magnitude=gradient_magnitude(expected(start).mean(axis=2).astype(np.uint8)),
    )
    assert fit.converged and fit.samples > 300
    errors = pixel_errors(item, fit.obj2cam, truth, intrinsics)
    assert errors.max() < 0.2, errors
    # the reported uncertainty is of the size of the error, not a thousand times smaller or larger
    position_sigma_mm = np.sqrt(np.trace(fit.covariance[3:, 3:]))
    assert 0.005 < position_sigma_mm < 1.0


def test_find_points_proposes_features_within_a_pixel_and_says_why_not_the_rest(look):
    image, intrinsics, item, model, truth, expected = look
    result = find_points(image, intrinsics, item, model, expected=expected)
    assert result.found, result.message
    truth_px = {n: project_points(item.features[n][None], truth, intrinsics)[0] for n in item.features}
    errors = {p.feature: float(np.linalg.norm(p.uv_px - truth_px[p.feature])) for p in result.proposals}
    assert len(result.proposals) >= 6 and max(errors.values()) < 1.1, errors
    assert {p.feature for p in result.proposals} | {m.feature for m in result.missed} == set(item.features)
    assert all(m.reason for m in result.missed)
    kinds = {p.feature: p.kind for p in result.proposals}
    assert kinds.get("boss_bottom_left", "circle") == "circle" and kinds.get("plate_bottom_left", "corner") == "corner"


@pytest.mark.parametrize("factor", [1.0, 2.0], ids=["typical errors", "twice the typical errors"])
def test_close_up_the_camera_s_move_is_found_not_only_its_turn(factor):
    """At the task location itself the fixture is 177 mm away and the gripper's fingers stand in front of
    the pin: the robot's error shifts the pin and the plate by different amounts. A start found as a 2D
    shift of the image settled 2.4 mm from the true pose with half its samples on the plate (the demo's
    first look: 2.3 mm after correction, 'ok'); the camera poses searched from the model's must find it."""
    for image, intrinsics, item, model, truth, expected in _look(factor, "task"):
        assert pixel_errors(item, model, truth, intrinsics).max() > 40.0  # the robot's error, before
        result = find_points(image, intrinsics, item, model, expected=expected)
        assert result.found, result.message
        assert result.edges.settled and result.edges.inlier_share > 0.75
        camera_error_mm = np.linalg.norm(np.linalg.inv(result.edges.obj2cam)[:3, 3] - np.linalg.inv(truth)[:3, 3])
        assert camera_error_mm < 0.1
        errors = {
            p.feature: float(np.linalg.norm(p.uv_px - project_points(p.point_mm[None], truth, intrinsics)[0]))
            for p in result.proposals
        }
        assert len(errors) >= 7 and max(errors.values()) < 1.0, errors


def test_a_frame_without_the_target_says_so():
    for image, intrinsics, item, model, truth, expected in _look(1.0):
        blank = np.full_like(image, 90)
        result = find_points(blank, intrinsics, item, model, expected=expected)
        assert not result.found and "pick the points by hand" in result.message and not result.proposals


def test_the_edge_fit_settles_on_an_aliased_frame():
    """A point-sampled frame (no pixel integration: what a sharp lens on a sensor with a small fill
    factor gives) quantises the edges; plain Gauss-Newton then steps back and forth between two poses
    for ever. These errors made that two-cycle: the fit must settle between them, on the part."""
    bed = TestBed.create(errors=RobotErrors.typical(2, n_joints=6))
    cell = bed.workcell
    q = solve_ik(bed.model_robot, cell.task("oru_1_grasp").approach2base, np.array(cell.home_joints_deg, float)).q_deg
    bed.joints_deg = q
    camera = bed.camera(look=CameraLook(supersample=1))
    image = camera.read().image
    truth = np.linalg.inv(camera.last_truth.cam2world) @ cell.component(TARGET).item2world
    camera.close()
    item = cell.component(TARGET)
    model = np.linalg.inv(bed.model_cam2world(q)) @ item.item2world
    view = ModelView(bed.intrinsics)
    try:
        expected = view.of_cell(cell.components, bed.visuals_for_model(), q, item.item2world)
        result = find_points(image, bed.intrinsics, item, model, expected=expected)
    finally:
        view.close()
    assert result.edges is not None and result.edges.converged and result.edges.settled, result.message
    assert pixel_errors(item, result.edges.obj2cam, truth, bed.intrinsics).max() < 0.5
