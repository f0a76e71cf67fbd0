"""The robot calibration on the cold cell, start to end, as ``videocal calibrate-robot sim``, the
bench and the tests run it: plan with the nominal model, view and detect with the true camera,
calibrate the intrinsics from the same views, identify, score against the truth."""

from __future__ import annotations

from dataclasses import dataclass

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.robot_calibration.identification import RobotCalibration, identify
from calib_core.robot_calibration.pose_planner import PosePlan, plan_poses
from calib_core.robot_calibration.report import score_against_truth
from calib_core.robot_calibration.sim_views import simulated_pose_views
from calib_core.testbed.cold_cell import cold_test_bed
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from calib_core.vision.intrinsics_calibration import IntrinsicsCalibration, calibrate_intrinsics

HELD_OUT = 20
"""Planned poses not used for the calibration: the truth is compared there."""


@dataclass(frozen=True)
class ColdRun:
    result: RobotCalibration
    intrinsics: IntrinsicsCalibration
    plan: PosePlan
    rejected: list[str]
    score: dict
    nominal_robot: object


def calibrate_cold_cell(views: int = 40, seed: int = 0, *, with_intrinsics: bool = False, progress=None, say=lambda text: None) -> ColdRun:
    bed, truth = cold_test_bed(seed=seed)
    nominal = load_intrinsics(bed.workcell.intrinsics_path)
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, bed.workcell, bed.model_robot)
    say(f"planning {views} poses...")
    wanted = views + HELD_OUT
    plan = plan_poses(bed.model_robot, nominal, spec, board2base, wanted, start_deg=bed.workcell.home_joints_deg, candidates=min(160, 3 * wanted), seed=seed)
    calibration_q, held_out = plan.joints_deg[:views], plan.joints_deg[views:]
    board_views, pose_views, rejected = simulated_pose_views(bed, spec, board2base, calibration_q, seed=seed, progress=progress)
    intrinsics = calibrate_intrinsics(board_views, spec)
    say(f"intrinsics: RMS {intrinsics.rms_px:.3f} px from {len(board_views)} views; identifying...")
    result = identify(bed.model_robot, intrinsics.intrinsics, pose_views, with_intrinsics=with_intrinsics)
    score = score_against_truth(result, bed, truth, held_out, board2base)
    return ColdRun(result, intrinsics, plan, rejected, score, bed.model_robot)
