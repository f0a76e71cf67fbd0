"""Hand-eye data from the simulated test bed: the robot looks at a board from several poses."""

from __future__ import annotations

import numpy as np

from calib_core.frames import make_transform
from videocal_sim.sim_camera import SimulatedCamera
from videocal_sim.test_bed import TestBed
from calib_core.vision.board import BoardSpec, board_item
from calib_core.vision.board_placement import FACING_ROBOT, board_from_centre, board_view_joints


def board_facing_robot(spec: BoardSpec) -> np.ndarray:
    """``board2base``: the board upright 950 mm in front of the bundled robot, centred at 1 m
    height, facing -x (the bundled cell's ``hand_eye_board``)."""
    return board_from_centre(spec, make_transform(FACING_ROBOT, [950.0, 0.0, 1000.0]))


def hand_eye_poses(
    bed: TestBed, spec: BoardSpec, board2base: np.ndarray, n: int = 10, seed: int = 0
) -> list[np.ndarray]:
    """Joint vectors (deg) from which the modelled camera of the test bed looks at the board."""
    return board_view_joints(bed.model_robot, bed.workcell.home_joints_deg, spec, board2base, n, seed)


def simulated_hand_eye_images(
    bed: TestBed, spec: BoardSpec, joints: list[np.ndarray], board2base: np.ndarray, seed: int = 0
):
    """(name, RGB image, commanded joints) for each pose, seen by the true camera of the test bed."""
    board = board_item(spec, board2base)
    camera = SimulatedCamera(
        bed.intrinsics,
        lambda q: bed.true_scene(q) + [board],
        bed.true_cam2world,
        lambda: bed.joints_deg.copy(),
        seed=seed,
    )
    images = []
    for k, q in enumerate(joints):
        bed.joints_deg = np.asarray(q, dtype=float)
        images.append((f"pose_{k + 1:02d}", camera.read().image, bed.joints_deg.copy()))
    camera.close()
    return images


def calibrate_simulated_hand_eye(
    *, board: str | None, workcell, robot_errors: bool, poses: int, detector_params, pose_sigma_mm: float
):
    """``calibrate-hand-eye sim``: the test bed's robot views the board from ``poses`` poses; returns
    ``(HandEyeResult, {"mm", "deg"} against the true mounting)``. The truth only scores."""
    import sys

    from calib_core.errors import VideocalError
    from calib_core.frames import concat, invert, pose_difference
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.board_placement import board_in_cell
    from calib_core.vision.hand_eye import calibrate_hand_eye
    from calib_core.vision.intrinsics_calibration import BoardView, detect_view
    from calib_core.vision.target_detection import load_detector_settings
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell
    from videocal_sim.true_robot import RobotErrors

    spec = parse_board(board or DEFAULT_SPEC)
    cell = load_workcell(workcell or DEFAULT_WORKCELL)
    typical = RobotErrors.typical(0, n_joints=cell.load_robot().n_joints)
    errors = (
        typical
        if robot_errors
        else RobotErrors(hand_eye_xyz_mm=typical.hand_eye_xyz_mm, hand_eye_rpy_deg=typical.hand_eye_rpy_deg)
    )
    bed = TestBed.create(cell, errors=errors)
    board2base = board_in_cell(spec, cell, bed.model_robot)
    joints = hand_eye_poses(bed, spec, board2base, poses)
    if len(joints) < 3:
        raise VideocalError(f"only {len(joints)} reachable poses see the board")
    print(f"rendering {len(joints)} poses...", file=sys.stderr)
    detect = spec.detector(load_detector_settings(detector_params) if detector_params else None)
    views, flanges = [], []
    for name, image, q in simulated_hand_eye_images(bed, spec, joints, board2base):
        v = detect_view(name, image, spec, detect)
        if isinstance(v, BoardView):
            views.append(v)
            flanges.append(bed.model_robot.fk(q, "flange"))
        else:
            print(f"rejected {name}: {v.reason}", file=sys.stderr)
    result = calibrate_hand_eye(views, flanges, spec, bed.intrinsics, pose_sigma_mm=pose_sigma_mm)
    true_robot = bed.true_robot.robot
    true_cam2flange = concat(true_robot.frame_placement("camera"), invert(true_robot.frame_placement("flange")))
    d, r = pose_difference(result.cam2flange, true_cam2flange)
    return result, {"mm": float(np.linalg.norm(d)), "deg": float(np.linalg.norm(r))}
