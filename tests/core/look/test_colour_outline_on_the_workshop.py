"""The outline by colour on the workshop's simulated camera (parts printed, lamps casting shadows, a softer lens and a
ring light), at the paper's task location. Where the colours end lies inward of the edge there (the blurred pixels
astride it are mixed colours, likelier the surroundings'): the fit measures that offset against the gradients beside
the outline and takes it out, so the fixture's creases join and its depth is right. Without it, the camera was 0.18 mm
off here and a boss proposed 1.2 px from its truth (2 mm and 2.6 px from other poses). The truth only scores."""

import numpy as np

from calib_core.camera.projection import project_points
from calib_core.render.model_view import ModelView
from calib_core.robot import solve_ik
from calib_core.look.find_points import find_points
from videocal_sim.real_look import make_less_kind
from videocal_sim.test_bed import TestBed


def _fixture_by_colour(place: str):
    """Find points by colour on the workshop camera (no form error: the truth's features stay where the CAD has them)
    with the robot's typical errors, at the paper's task location (``tcp``) or its approach: (bed, the fixture, the
    result, the true cam2world)."""
    bed = TestBed.create()
    make_less_kind(bed, form_error_mm=0.0)
    cell = bed.workcell
    item = cell.component("oru_1_fixture")
    task = cell.task("oru_1_grasp")
    target = task.tcp2base if place == "tcp" else task.approach2base
    q = solve_ik(bed.model_robot, target, np.array(cell.home_joints_deg, float)).q_deg
    bed.joints_deg = q
    camera = bed.camera()
    view = ModelView(bed.intrinsics)
    try:
        frame = camera.read()
        model = np.linalg.inv(bed.model_cam2world(q)) @ item.item2world
        expected = view.of_cell(cell.components, bed.visuals_for_model(), q, item.item2world)
        result = find_points(frame.image, bed.intrinsics, item, model, expected=expected, by_colour=True)
    finally:
        view.close()
        camera.close()
    return bed, item, result, camera.last_truth.cam2world


def test_the_fixture_by_its_colours_on_the_workshop_camera_is_where_it_is():
    bed, item, result, truth_cam2world = _fixture_by_colour("tcp")
    truth = np.linalg.inv(truth_cam2world) @ item.item2world
    assert result.found and result.edges is not None and result.edges.settled, result.message
    fitted_cam2world = item.item2world @ np.linalg.inv(result.edges.obj2cam)
    assert np.linalg.norm(fitted_cam2world[:3, 3] - truth_cam2world[:3, 3]) < 0.1
    names = list(item.features)
    true_px = project_points(np.array([item.features[n] for n in names]), truth, bed.intrinsics)
    errors = {p.feature: float(np.linalg.norm(p.uv_px - true_px[names.index(p.feature)])) for p in result.proposals}
    assert len(errors) >= 8 and max(errors.values()) < 1.0, errors


def test_the_fixture_by_its_colours_from_the_approach_states_a_1_sigma_its_error_falls_within():
    """From the approach (about 350 mm), the outline by colour puts the camera about 1.5 mm off: the colours end
    inward of the lit top bevel by more than the median shift takes out. The fit says so itself: where the strongest
    gradient lies near its colour steps moves the pose that far, and that disagreement is in its covariance (without
    it the error was 3 times the stated 1-sigma)."""
    from calib_core.look.edge_solution import edge_solution

    bed, item, result, truth_cam2world = _fixture_by_colour("approach")
    fit = result.edges
    assert fit is not None and fit.settled and fit.outline_bias is not None, result.message
    error_mm = np.linalg.norm((item.item2world @ np.linalg.inv(fit.obj2cam))[:3, 3] - truth_cam2world[:3, 3])
    stated_mm = np.linalg.norm(edge_solution(fit, bed.intrinsics).uncertainty.std_camera_position_mm)
    # the gradients' pose is the stated bias away; the error lies within three of the stated 1-sigma
    assert np.linalg.norm(fit.outline_bias[3:]) > 0.2 * error_mm, (fit.outline_bias, error_mm)
    assert error_mm < 3.0 * stated_mm, (error_mm, stated_mm)


def test_parts_a_millimetre_off_their_cad_at_full_size_are_looked_at_on_the_image_halved():
    """The workshop's parts printed up to 1 mm off their CAD (stated: 0.5 mm, 1-sigma), Find points as the window runs
    it (edges by gradient), at full size from the task location: the stated tolerance is 3.3 px there, more than the
    edge fit's finest window, and the fixture's bent outline tilted the fit (refused: RMS 1.2 px against 0.5). On the
    image halved the bend is within the window: the fixture is found, its centre within half a millimetre of where it
    truly is (the model puts it 9 mm off), the proposals in the whole image's pixels, and the message says where it
    looked and why."""
    from calib_core.look.edge_refinement import FINEST_WINDOW_PX
    from calib_core.look.form_tolerance import form_error_px
    from videocal_sim.real_look import WORKSHOP_FORM_ERROR_MM, WORKSHOP_FORM_TOLERANCE_MM

    bed = TestBed.create()
    make_less_kind(bed)
    cell = bed.workcell
    item = cell.component("oru_1_fixture")
    item.form_tolerance_mm = WORKSHOP_FORM_TOLERANCE_MM
    q = solve_ik(bed.model_robot, cell.task("oru_1_grasp").tcp2base, np.array(cell.home_joints_deg, float)).q_deg
    bed.joints_deg = q
    camera = bed.camera()
    view = ModelView(bed.intrinsics)
    try:
        model = np.linalg.inv(bed.model_cam2world(q)) @ item.item2world
        expected = view.of_cell(cell.components, bed.visuals_for_model(), q, item.item2world)
        result = find_points(camera.read().image, bed.intrinsics, item, model, expected=expected)
    finally:
        view.close()
        camera.close()
    assert form_error_px(item, model, bed.intrinsics) > FINEST_WINDOW_PX
    assert result.found and result.edges is not None and result.edges.settled, result.message
    assert result.edges.px_scale == 2.0
    assert (
        "(looked at the image at half its size, where the figures above are measured: its stated form tolerance, "
        in (result.message)
    )
    truth = np.linalg.inv(camera.last_truth.cam2world) @ item.item2world
    centre = item.mesh.vertices.mean(axis=0)
    assert np.linalg.norm(concat_point(result.obj2cam, centre) - concat_point(truth, centre)) < 0.6
    assert np.linalg.norm(concat_point(model, centre) - concat_point(truth, centre)) > 5.0
    # the proposals where the whole camera sees the part: each within the part's own bend (1 mm) of its CAD feature
    names = list(item.features)
    true_px = project_points(np.array([item.features[n] for n in names]), truth, bed.intrinsics)
    form_px = form_error_px(item, truth, bed.intrinsics)
    errors = [float(np.linalg.norm(p.uv_px - true_px[names.index(p.feature)])) for p in result.proposals]
    assert len(errors) >= 4 and max(errors) < WORKSHOP_FORM_ERROR_MM * form_px / WORKSHOP_FORM_TOLERANCE_MM, errors


def concat_point(obj2cam: np.ndarray, point_mm: np.ndarray) -> np.ndarray:
    return obj2cam[:3, :3] @ point_mm + obj2cam[:3, 3]
