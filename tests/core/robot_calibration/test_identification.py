"""Robot calibration's maths on exact and noisy synthetic views of a board (no rendering): known
answers, the parameter round trip, the observability of known redundancies, honest sigmas, and the
calibrated URDF read back by the loader every other part uses."""

import numpy as np
import pytest

from tests.core.robot_calibration.board_scenes import SPEC, board_views, cold_cell_with_board

from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference
from calib_core.robot.model import load_robot
from calib_core.robot_calibration.identification import RobotCalibrationError, identify
from calib_core.robot_calibration.observations import CELL, PoseView
from calib_core.robot_calibration.parameters import CorrectedRobot
from calib_core.robot_calibration.pose_planner import plan_poses
from calib_core.robot_calibration.report import calibrated_urdf, save_robot_calibration
from calib_core.workcell import load_workcell


@pytest.fixture(scope="module")
def setup():
    return cold_cell_with_board(50)


def test_exact_views_of_the_true_robot_give_its_camera_poses_exactly(setup):
    """Known answer: the true robot's typical errors lie in the error model's span, so with exact
    pixels the held-out camera poses (relative to the board, what board views determine) come back to
    round-off, from 7 px of nominal-model error."""
    bed, board2base, joints = setup
    views = board_views(bed.true_cam2world, joints[:35], board2base, bed.intrinsics)
    result = identify(bed.model_robot, bed.intrinsics, views)
    assert result.start_rms_px > 3.0 and result.rms_px < 1e-6
    for q in joints[35:]:
        est = invert(result.board2base) @ result.robot.fk(q, "camera")
        true = invert(board2base) @ bed.true_cam2world(q)
        d, r = pose_difference(est, true)
        assert np.linalg.norm(d) < 1e-5 and np.linalg.norm(r) < 1e-6


def test_the_board_absorbs_the_first_joint_and_the_report_says_so(setup):
    """A board at an unknown pose cannot tell where the robot's base is: every correction of the
    first joint's placement is a move of the whole robot, which the board's placement takes up."""
    bed, board2base, joints = setup
    result = identify(
        bed.model_robot, bed.intrinsics, board_views(bed.true_cam2world, joints[:30], board2base, bed.intrinsics)
    )
    names = result.names
    unidentified = {names[k] for k in result.observability.unidentified}
    assert {f"joint_1.{a}" for a in ("x_mm", "y_mm", "z_mm", "rx_mrad", "ry_mrad", "rz_mrad")} <= unidentified
    assert result.observability.rank == len(result.observability.identified) < len(names)
    assert result.observability.directions and np.isfinite(result.observability.condition)
    assert all(np.isnan(result.sigmas[k]) and result.values[k] == 0.0 for k in result.observability.unidentified)


def test_parameters_come_back_from_views_made_with_them_and_their_sigmas_are_honest(setup):
    """The round trip in the model's own parameters: a robot made with random corrections of the
    identified subset, seen with 0.1 px noise, gives them back within their 1-sigma's reach."""
    bed, board2base, joints = setup
    probe = identify(
        bed.model_robot, bed.intrinsics, board_views(bed.true_cam2world, joints[:30], board2base, bed.intrinsics)
    )
    rng = np.random.default_rng(5)
    truth = np.zeros(len(probe.names))
    truth[probe.observability.identified] = rng.normal(0.0, 0.5, len(probe.observability.identified))
    made = CorrectedRobot(bed.model_robot)
    made.set(truth)
    z = []
    for seed in range(3):
        result = identify(
            bed.model_robot,
            bed.intrinsics,
            board_views(made.cam2base, joints[:30], board2base, bed.intrinsics, 0.1, seed),
            parameters=probe.identified_names,
        )
        assert result.observability.identified == probe.observability.identified
        ids = result.observability.identified
        z.extend(((result.values[ids] - truth[ids]) / result.sigmas[ids]).tolist())
        assert result.noise_px == pytest.approx(0.1, rel=0.1)
    z = np.abs(np.array(z))
    assert np.mean(z < 3.0) > 0.95 and 0.5 < np.sqrt(np.mean(z**2)) < 1.6


def test_surveyed_cell_features_tie_the_robot_to_the_cell(setup):
    """With views of points surveyed in the base frame, the first joint's placement (the base) is
    determined too, and the camera comes back in the base frame itself."""
    bed, board2base, joints = setup
    views = board_views(bed.true_cam2world, joints[:30], board2base, bed.intrinsics)
    # The board's corners as if surveyed: known in the base frame.
    pts = apply(board2base, SPEC.corners_mm())
    for k, q in enumerate(joints[30:40]):
        px = project(apply(invert(bed.true_cam2world(q)), pts), bed.intrinsics)
        views.append(PoseView(f"s{k}", np.asarray(q), pts, px, target=CELL))
    result = identify(bed.model_robot, bed.intrinsics, views)
    assert "joint_1.x_mm" in result.identified_names
    for q in joints[40:]:
        d, r = pose_difference(result.robot.fk(q, "camera"), bed.true_cam2world(q))
        assert np.linalg.norm(d) < 1e-4 and np.linalg.norm(r) < 1e-5


def test_the_calibrated_urdf_loads_and_moves_like_the_calibrated_model(setup, tmp_path):
    bed, board2base, joints = setup
    result = identify(
        bed.model_robot, bed.intrinsics, board_views(bed.true_cam2world, joints[:30], board2base, bed.intrinsics)
    )
    yaml_path, urdf_path = save_robot_calibration(tmp_path, result, bed.model_robot)
    assert yaml_path.is_file() and urdf_path.name == "videocal_arm_calibrated.urdf"
    text, left = calibrated_urdf(bed.model_robot, result.robot)
    assert left == []
    back = load_robot(urdf_path)
    rng = np.random.default_rng(0)
    for _ in range(10):
        q = rng.uniform(-90, 90, 6)
        for frame in ("flange", "camera", "tcp"):
            d, r = pose_difference(back.fk(q, frame), result.robot.fk(q, frame))
            assert np.linalg.norm(d) < 1e-4 and np.linalg.norm(r) < 1e-5


def test_too_few_views_are_refused(setup):
    bed, board2base, joints = setup
    with pytest.raises(RobotCalibrationError, match="at least 6"):
        identify(
            bed.model_robot, bed.intrinsics, board_views(bed.true_cam2world, joints[:3], board2base, bed.intrinsics)
        )


def test_the_planned_poses_see_the_board_and_inform_more_than_arbitrary_ones(setup):
    bed, board2base, joints = setup
    plan = plan_poses(bed.model_robot, bed.intrinsics, SPEC, board2base, 12, start_deg=np.zeros(6), candidates=40)
    assert len(plan.joints_deg) == 12
    for q in plan.joints_deg:
        assert np.all(bed.model_robot.within_limits(q))
        px = project(apply(invert(bed.model_robot.fk(q, "camera")) @ board2base, SPEC.corners_mm()), bed.intrinsics)
        assert np.all(bed.intrinsics.contains(px, 30.0))
    arbitrary = plan_poses(bed.model_robot, bed.intrinsics, SPEC, board2base, 40, start_deg=np.zeros(6), candidates=40)
    first12 = identify(
        bed.model_robot,
        bed.intrinsics,
        board_views(bed.true_cam2world, arbitrary.joints_deg[:12], board2base, bed.intrinsics, 0.1),
    )
    chosen = identify(
        bed.model_robot,
        bed.intrinsics,
        board_views(bed.true_cam2world, plan.joints_deg, board2base, bed.intrinsics, 0.1),
    )
    # The D-optimal set determines the parameters better: smaller sigmas on what both identify.
    common = sorted(set(first12.observability.identified) & set(chosen.observability.identified))
    assert np.median(chosen.sigmas[common] / first12.sigmas[common]) < 1.0


def test_the_plan_reaches_the_image_corners(setup, monkeypatch):
    """The same views calibrate the lens: turned off the board's centre, the planned views put
    corners in most of the image's cells (where the distortion is learnt), far more than views
    aimed at the board's centre."""
    from calib_core.robot_calibration import pose_planner
    from calib_core.vision.intrinsics_calibration import BoardView, coverage

    bed, board2base, joints = setup
    size = (bed.intrinsics.width, bed.intrinsics.height)

    def covered():
        plan = plan_poses(bed.model_robot, bed.intrinsics, SPEC, board2base, 20, start_deg=np.zeros(6), candidates=60)
        views = [
            BoardView(
                str(k),
                project(apply(invert(bed.model_robot.fk(q, "camera")) @ board2base, SPEC.corners_mm()), bed.intrinsics),
                np.arange(len(SPEC.corners_mm())),
                size,
            )
            for k, q in enumerate(plan.joints_deg)
        ]
        return coverage(views, size)

    turned = covered()
    monkeypatch.setattr(pose_planner, "OFF_CENTRE_DEG", 0.0)
    centred = covered()
    assert turned > 0.85 and turned > centred + 0.15, (turned, centred)


def test_the_tie_sees_components_off_the_line_of_the_tasks():
    """The bundled cell's two task fixtures stand one above the other: the base's turn about that
    line would rest on edge-fit orientations alone. The tie's targets add a component off it."""
    from calib_core.robot_calibration.cell_views import _centroid, surveyed_targets

    cell = load_workcell()
    robot = cell.load_robot()
    targets = surveyed_targets(robot, cell)
    names = [n for n, _ in targets]
    assert names[:2] == ["oru_1_fixture", "oru_2_fixture"] and len(names) >= 3
    c = np.array([_centroid(cell.component(n)) for n in names])
    line = (c[1] - c[0]) / np.linalg.norm(c[1] - c[0])
    off = [np.linalg.norm(np.cross(p - c[0], line)) for p in c[2:]]
    assert max(off) > 500.0
    for _, camera2base in targets:  # each camera looks at its component
        assert np.isclose(np.linalg.det(camera2base[:3, :3]), 1.0)
