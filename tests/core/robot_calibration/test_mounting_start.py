"""Where the identification starts the camera's mounting: a cell whose camera is modelled far from where it is
mounted (a starting cell's guess) is started from the mounting the board views give, and says so; a cell whose
mounting is near is kept."""

import re

import numpy as np
import pytest

from calib_core.camera.projection import project
from calib_core.frames import apply, invert, make_transform, pose_difference
from calib_core.robot_calibration.identification import identify
from calib_core.robot_calibration.mounting_start import FAR_DEG, FAR_MM, mounting_from_views
from calib_core.robot_calibration.observations import PoseView
from calib_core.vision.board_placement import board_view_joints
from calib_core.workcell import load_workcell
from scipy.spatial.transform import Rotation
from tests.core.robot_calibration.board_scenes import SPEC, board_views, cold_cell_with_board


@pytest.fixture(scope="module")
def setup():
    return cold_cell_with_board(50)


def _guessed(robot, turn_deg: float, move_mm: float):
    """A copy of ``robot`` whose camera is modelled ``turn_deg`` about a slanted axis and ``move_mm`` away from where
    it is (a starting cell's guess)."""
    guessed = robot.copy()
    off = make_transform(
        Rotation.from_rotvec(np.radians(turn_deg) * np.array([0.6, 0.0, 0.8])).as_matrix(), [move_mm, 0, 0]
    )
    guessed.set_frame_placement("camera", off @ robot.frame_placement("camera"))
    return guessed


def test_the_views_give_the_mounting_they_were_made_with(setup):
    """Known answer: views made through the model robot itself give back its camera's placement on its joint, from
    a cell that guessed it 140 deg and 120 mm off (the guess does not enter the answer)."""
    bed, board2base, joints = setup
    robot = bed.model_robot
    views = board_views(lambda q: robot.fk(q, "camera"), joints[:30], board2base, bed.intrinsics)
    found = mounting_from_views(_guessed(robot, 140.0, 120.0), bed.intrinsics, views)
    d_mm, r_deg = pose_difference(found, robot.frame_placement("camera"))
    assert np.linalg.norm(d_mm) < 1e-3 and np.linalg.norm(r_deg) < 1e-4


def test_a_mounting_guessed_far_off_is_started_from_the_views_and_said(setup):
    """Twelve views with the joints read to 0.3 deg and the corners to 0.3 px (as few and as rough as a real Franka
    set's), from a cell whose camera is guessed 136 deg and 115 mm off: the fit ends where it ends from the right
    mounting, and says the cell's was far off. From the guess alone it ends in another minimum, twice as far off."""
    bed, board2base, _ = setup
    rng = np.random.default_rng(0)
    joints = board_view_joints(bed.model_robot, load_workcell().home_joints_deg, SPEC, board2base, 12, seed=0)
    pts = SPEC.corners_mm()
    views = [
        PoseView(
            f"v{k}",
            np.asarray(q) + rng.normal(0.0, 0.3, len(q)),
            pts,
            project(apply(invert(bed.true_cam2world(q)) @ board2base, pts), bed.intrinsics)
            + rng.normal(0.0, 0.3, (len(pts), 2)),
        )
        for k, q in enumerate(joints)
    ]
    from_right = identify(bed.model_robot, bed.intrinsics, views)
    guessed = _guessed(bed.model_robot, 136.0, 115.0)
    result = identify(guessed, bed.intrinsics, views)
    assert result.start_rms_px > 100.0
    assert result.rms_px == pytest.approx(from_right.rms_px, rel=1e-3)
    said = [w for w in result.warnings if w.startswith("the cell's camera mounting lies")]
    assert len(said) == 1
    mm, deg = (float(x) for x in re.match(r"the cell's camera mounting lies (\d+) mm and (\d+) deg", said[0]).groups())
    d_mm, r_deg = pose_difference(guessed.frame_placement("camera"), bed.model_robot.frame_placement("camera"))
    # how far the guess was, as the noisy views say
    assert abs(mm - np.linalg.norm(d_mm)) < 10.0 and abs(deg - np.linalg.norm(r_deg)) < 3.0


def test_a_mounting_near_the_views_is_kept(setup):
    """The model robot's own mounting (a few mm from the views' through the robot's errors) is the start: nothing is
    said, and the views' mounting lies within the bound that keeps it."""
    bed, board2base, joints = setup
    views = board_views(bed.true_cam2world, joints[:30], board2base, bed.intrinsics)
    d_mm, r_deg = pose_difference(
        mounting_from_views(bed.model_robot, bed.intrinsics, views), bed.model_robot.frame_placement("camera")
    )
    assert np.linalg.norm(d_mm) < FAR_MM and np.linalg.norm(r_deg) < FAR_DEG
    result = identify(bed.model_robot, bed.intrinsics, views)
    assert not any("camera mounting lies" in w for w in result.warnings)
