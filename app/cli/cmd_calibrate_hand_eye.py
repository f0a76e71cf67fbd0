"""``videocal calibrate-hand-eye sim --out FILE``: the camera's mounting on the flange (``cam2flange``)
from robot poses looking at a ChArUco board, here on the simulated test bed (its truth printed beside)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from calib_core.errors import VideocalError
from app.cli.options import bounded_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source", choices=("sim",), help="'sim': the simulated test bed (a real robot and camera need the window's capture mode, not built yet)")
    parser.add_argument("--workcell", type=Path, help="the cell whose robot and camera are simulated (default: the bundled one); the board stands where its hand_eye_board says, or in front of the robot")
    parser.add_argument("--board", default="charuco:9x7:30:22:DICT_5X5_100")
    parser.add_argument("--poses", type=bounded_int(3, 200), default=10, help="robot poses to view the board from (3 to 200)")
    parser.add_argument("--out", type=Path, required=True, help="YAML file for cam2flange (xyz mm, rpy deg) and its 1-sigma")
    parser.add_argument("--robot-errors", action="store_true", help="give the simulated robot its joint, link and base errors too (shows why hand-eye calibration needs accurate kinematics)")


def run(args: argparse.Namespace) -> int:
    from calib_core.frames import pose_difference, xyz_rpy_from_transform
    from calib_core.testbed.test_bed import TestBed
    from calib_core.testbed.true_robot import RobotErrors
    from calib_core.vision.board import BoardSpec
    from calib_core.vision.hand_eye import calibrate_hand_eye
    from calib_core.vision.hand_eye_io import save_hand_eye
    from calib_core.vision.board_placement import board_in_cell
    from calib_core.vision.hand_eye_sim import hand_eye_poses, simulated_hand_eye_images
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell
    from calib_core.vision.intrinsics_calibration import BoardView, detect_view

    spec = BoardSpec.parse(args.board)
    cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
    typical = RobotErrors.typical(0, n_joints=cell.load_robot().n_joints)
    errors = typical if args.robot_errors else RobotErrors(hand_eye_xyz_mm=typical.hand_eye_xyz_mm, hand_eye_rpy_deg=typical.hand_eye_rpy_deg)
    bed = TestBed.create(cell, errors=errors)
    board2base = board_in_cell(spec, cell, bed.model_robot)
    joints = hand_eye_poses(bed, spec, board2base, args.poses)
    if len(joints) < 3:
        raise VideocalError(f"only {len(joints)} reachable poses see the board")
    print(f"rendering {len(joints)} poses...", file=sys.stderr)
    views, flanges = [], []
    for name, image, q in simulated_hand_eye_images(bed, spec, joints, board2base):
        v = detect_view(name, image, spec)
        if isinstance(v, BoardView):
            views.append(v)
            flanges.append(bed.model_robot.fk(q, "flange"))
        else:
            print(f"rejected {name}: {v.reason}", file=sys.stderr)
    result = calibrate_hand_eye(views, flanges, spec, bed.intrinsics)
    save_hand_eye(args.out, result)
    xyz, _ = xyz_rpy_from_transform(result.cam2flange)
    true = np.linalg.inv(bed.true_robot.robot.frame_placement("flange")) @ bed.true_robot.robot.frame_placement("camera")
    d, r = pose_difference(result.cam2flange, true)
    print(f"{result.views} poses, RMS {result.rms_px:.3f} px")
    print(f"cam2flange xyz {', '.join(f'{v:.3f}' for v in xyz)} mm (1-sigma {', '.join(f'{v:.3f}' for v in result.std_xyz_mm)})")
    print(f"error against the test bed's truth: {np.linalg.norm(d):.3f} mm, {np.linalg.norm(r):.4f} deg")
    for w in result.warnings:
        print(f"warning: {w}")
    print(f"wrote {args.out}")
    return 0
