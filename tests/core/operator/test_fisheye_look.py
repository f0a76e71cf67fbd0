"""A look through a fisheye (equidistant) lens, the whole chain: the simulated camera renders through it,
picks are made on its image, Find points and its edge fit work on it, and the solve measures the camera as through
the bundled lens. The lens is the bundled camera's focal length and principal point with OpenCV's fisheye model
(its corners 175 px from where a pinhole would put them). The truth only scores."""

from calib_core.calibration.commands import ClearPairs
import numpy as np
import pytest

from calib_core.calibration.verdict import Verdict
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.operator.core import OperatorCore
from calib_core.robot import solve_ik
from tests.core.operator.perfect_operator import pick_all
from tests.core.operator.still_robot import frame_now, still_for
from videocal_sim.sim_site import simulated_cell

FISHEYE = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960, (-0.01, 0.002, 0.0, 0.0), "equidistant")


@pytest.fixture(scope="module")
def fisheye_look():
    cell, site = simulated_cell(intrinsics=FISHEYE)
    core = OperatorCore(cell, site)
    q = solve_ik(core.robot, core.task.approach2base, core.cell.home_joints).q_deg
    site.bed.joints_deg = q
    camera = site.camera_factory()()
    still_for(core, joints_deg=q)
    frame = frame_now(core, index=1, image=camera.read().image)
    yield core, site, q, frame
    camera.close()


def _camera_error(core, site, q, estimate) -> tuple[float, float]:
    true_cam = site.bed.true_cam2world(q)
    return (
        float(np.linalg.norm(estimate.cam2world_measured[:3, 3] - true_cam[:3, 3])),
        float(np.linalg.norm(estimate.cam2world_model[:3, 3] - true_cam[:3, 3])),
    )


def test_the_lens_moves_a_feature_by_pixels_and_the_cell_uses_it(fisheye_look):
    core, site, q, frame = fisheye_look
    fixture = core.workcell.component(core.task.component)
    corner = apply(
        invert(site.bed.true_cam2world(q)), apply(fixture.item2world, fixture.features["plate_top_left"])[None]
    )
    # the same point through the fisheye and through a pinhole of its focal length lands pixels apart
    assert np.linalg.norm(project(corner, FISHEYE) - project(corner, FISHEYE.without_distortion())) > 5.0
    assert core.intrinsics.model == "equidistant" and frame.image.shape == (960, 1280, 3)


def test_hand_picks_on_the_fisheye_image_solve_to_the_true_camera(fisheye_look):
    core, site, q, _ = fisheye_look
    core.session.undo.push(ClearPairs(core.session.pairs))
    pick_all(core, site.bed, q)
    estimate = core.picking.calibrate()
    error, model_error = _camera_error(core, site, q, estimate)
    assert error < 0.1 and model_error > 3.0, (error, model_error)


def test_find_points_and_the_edge_fit_work_through_the_fisheye(fisheye_look):
    core, site, q, _ = fisheye_look
    core.session.undo.push(ClearPairs(core.session.pairs))
    found = core.finder.find_points()
    assert found.result.found, found.result.message
    core.finder.accept_found_points()
    estimate = core.picking.calibrate()
    assert core.session.result.verdict.verdict is Verdict.OK, core.session.result.verdict.text
    error, model_error = _camera_error(core, site, q, estimate)
    assert error < 2.0 and error < 0.3 * model_error, (error, model_error)
    core.finder.find_points()
    edges = core.finder.calibrate_on_edges()
    error, model_error = _camera_error(core, site, q, edges)
    assert error < 0.15, (error, model_error)
