"""Surveyed components seen as poses (their edge fits) in a robot calibration, on synthetic views (no
rendering): the poses follow the intrinsics when the identification corrects them (sensitivity by
finite differences against an exact re-solve, and a known answer for the principal point), and a
view that disagrees with the rest is left out by name."""

import cv2
import numpy as np
import pytest

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, invert, make_transform, pose_difference
from calib_core.robot_calibration.identification import identify, pose_residual, pose_sensitivity_to_intrinsics
from calib_core.robot_calibration.observations import ObjectPoseView, PoseView
from calib_core.robot_calibration.parameters import INTRINSICS, corrected_intrinsics
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell, board_view_joints
from calib_core.workcell import load_workcell

SPEC = parse_board(DEFAULT_SPEC)
# A component's features: a 80 x 60 x 40 mm block's corners and its top's centre.
FEATURES = np.array([[x, y, z] for x in (0, 80) for y in (0, 60) for z in (0, -40)] + [[40, 30, -40]], dtype=float)
COVARIANCE = np.diag([1e-8] * 3 + [1e-4] * 3)  # 0.1 mrad, 0.01 mm


@pytest.fixture(scope="module")
def setup():
    cell = load_workcell()
    bed = TestBed.create(cell, errors=RobotErrors.typical(1))
    board2base = board_in_cell(SPEC, cell, bed.model_robot)
    joints = board_view_joints(bed.model_robot, cell.home_joints_deg, SPEC, board2base, 52, seed=5)
    # Three components about the board, off one line: the base's six degrees of freedom from positions.
    components = [
        board2base @ make_transform(np.eye(3), offset)
        for offset in ([20.0, 20.0, 0.0], [160.0, 30.0, 0.0], [40.0, 110.0, 0.0])
    ]
    return bed, board2base, joints, components


def _start_intrinsics(truth: Intrinsics) -> Intrinsics:
    """What a calibration beforehand might have given: a few tenths of a pixel and thousandths off."""
    return corrected_intrinsics(truth, np.array([1.5, 1.2, -1.0, 0.8, 3.0, -2.0, 0.2, -0.2]))


def _board_views(bed, joints, board2base):
    pts = SPEC.corners_mm()
    return [
        PoseView(
            f"b{k}", np.asarray(q), pts, project(apply(invert(bed.true_cam2world(q)) @ board2base, pts), bed.intrinsics)
        )
        for k, q in enumerate(joints)
    ]


def _measured(obj2cam_true, truth: Intrinsics, start: Intrinsics) -> np.ndarray:
    """The pose a measurement through ``start`` finds for the object the true camera sees at ``obj2cam_true``."""
    px = project(apply(obj2cam_true, FEATURES), truth)
    rvec0 = cv2.Rodrigues(obj2cam_true[:3, :3])[0]
    _, rvec, tvec = cv2.solvePnP(
        FEATURES,
        px,
        start.K,
        start.dist_coeffs,
        rvec0,
        obj2cam_true[:3, 3].reshape(3, 1).copy(),
        useExtrinsicGuess=True,
    )
    return make_transform(cv2.Rodrigues(rvec)[0], tvec.ravel())


def _object_views(bed, joints, components, start, with_points=True):
    out = []
    for k, q in enumerate(joints):
        obj2base = components[k % len(components)]
        true = invert(bed.true_cam2world(q)) @ obj2base
        out.append(
            ObjectPoseView(
                f"component_{k}",
                np.asarray(q),
                _measured(true, bed.intrinsics, start),
                COVARIANCE,
                obj2base,
                points_mm=FEATURES if with_points else None,
            )
        )
    return out


def _camera_error_mm(result, bed, joints) -> float:
    return max(np.linalg.norm(pose_difference(result.robot.fk(q, "camera"), bed.true_cam2world(q))[0]) for q in joints)


def test_the_sensitivity_to_the_intrinsics_matches_a_re_solve_and_the_principal_point_known_answer(setup):
    bed, board2base, joints, components = setup
    obj2cam = invert(bed.true_cam2world(joints[0])) @ components[0]
    intr = bed.intrinsics
    S = pose_sensitivity_to_intrinsics(obj2cam, FEATURES, intr)
    assert S.shape == (6, len(INTRINSICS))
    # Known answer: the same pixels through a principal point 1 px to the right (u = fu x / z + cx)
    # are the view turned 1 / fu rad about the camera's y axis, the other way: a left perturbation's
    # pure rotation, which carries the object's position along (no translation of its own).
    cx = INTRINSICS.index("cx_px")
    assert S[1, cx] == pytest.approx(-1.0 / intr.fu, rel=0.05)
    assert np.linalg.norm(S[3:, cx]) < 0.1 * obj2cam[2, 3] / intr.fu
    # A second way: the exact re-solve for a correction of every kind at once agrees to first order.
    d = np.array([0.6, -0.4, 0.5, -0.3, 1.0, 0.5, 0.1, -0.1])
    exact = pose_residual(obj2cam, _measured(obj2cam, intr, corrected_intrinsics(intr, d)))
    assert np.linalg.norm(S @ d - exact) < 0.05 * np.linalg.norm(exact)
    assert np.linalg.norm(exact[3:]) > 0.05  # the change is not negligible: tenths of a millimetre


def test_component_poses_follow_the_corrected_intrinsics(setup):
    """Known answer: board views through the true camera, component poses measured through intrinsics
    a pixel off. Fitting the intrinsics with the robot corrects the board's share; the components'
    poses, carried over to the corrected intrinsics, then agree with it, and the camera comes back in
    the base frame itself. Without the carry-over they pull the tie by what the intrinsics moved."""
    bed, board2base, joints, components = setup
    start = _start_intrinsics(bed.intrinsics)
    board = _board_views(bed, joints[:30], board2base)
    carried = identify(
        bed.model_robot, start, board + _object_views(bed, joints[30:42], components, start), with_intrinsics=True
    )
    fixed = identify(
        bed.model_robot,
        start,
        board + _object_views(bed, joints[30:42], components, start, with_points=False),
        with_intrinsics=True,
    )
    assert (
        abs(carried.intrinsics.fu - bed.intrinsics.fu) < 0.05 and abs(carried.intrinsics.cx - bed.intrinsics.cx) < 0.05
    )
    assert _camera_error_mm(carried, bed, joints[42:]) < 0.01
    assert _camera_error_mm(fixed, bed, joints[42:]) > 5 * _camera_error_mm(carried, bed, joints[42:])
    assert carried.left_out == {}


def test_a_component_view_that_disagrees_is_left_out_by_name(setup):
    bed, board2base, joints, components = setup
    board = _board_views(bed, joints[:30], board2base)
    objects = _object_views(bed, joints[30:42], components, bed.intrinsics)
    bad = objects[4]
    wrong = (
        make_transform(cv2.Rodrigues(np.array([0.003, 0.0, 0.0]))[0], [0.8, 0.0, 0.0]) @ bad.obj2cam
    )  # an edge fit on the wrong edges
    objects[4] = ObjectPoseView(bad.name, bad.joints_deg, wrong, bad.covariance, bad.obj2base, points_mm=FEATURES)
    result = identify(bed.model_robot, bed.intrinsics, board + objects)
    assert list(result.left_out) == ["component_4"]
    assert any(w.startswith("component_4 left out: its pose is") for w in result.warnings)
    assert result.residual_weights[-6 * 8 : -6 * 7].max() == 0.0  # its rows carry no weight
    assert _camera_error_mm(result, bed, joints[42:]) < 0.01
