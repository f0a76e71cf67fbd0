"""The robot calibration on the cold cell, start to end, as ``videocal calibrate-robot sim``, the bench
and the tests run it: plan with the nominal model, view and detect with the true camera, calibrate
the intrinsics from the same views, identify; then the score against the truth, the one place here
that reads it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.frames import invert, pose_difference
from calib_core.robot_calibration.identification import RobotCalibration, identify
from calib_core.robot_calibration.pose_planner import PosePlan, plan_poses
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


def score_against_truth(result: RobotCalibration, bed, truth, held_out: list[np.ndarray], board2base_true: np.ndarray) -> dict:
    """How far the calibrated model is from the test bed's truth at ``held_out`` poses: the camera and
    the TCP relative to the board (what board views determine) and in the base frame, RMS mm and deg;
    the intrinsics' differences. Only for scoring."""

    def rms(pairs):
        a = np.array(pairs)
        return [round(float(np.sqrt(np.mean(a[:, 0] ** 2))), 4), round(float(np.sqrt(np.mean(a[:, 1] ** 2))), 5)]

    out = {}
    if held_out and result.board2base is not None:
        for frame in ("camera", "tcp"):
            rel, base, nominal = [], [], []
            for q in held_out:
                est, tru = result.robot.fk(q, frame), bed.true_robot.fk(q, frame)
                d, r = pose_difference(invert(result.board2base) @ est, invert(board2base_true) @ tru)
                rel.append((np.linalg.norm(d), np.linalg.norm(r)))
                d, r = pose_difference(est, tru)
                base.append((np.linalg.norm(d), np.linalg.norm(r)))
                d, r = pose_difference(bed.model_robot.fk(q, frame), tru)
                nominal.append((np.linalg.norm(d), np.linalg.norm(r)))
            out[f"{frame}_in_board_frame_mm_deg"] = rms(rel)
            out[f"{frame}_in_base_frame_mm_deg"] = rms(base)
            out[f"{frame}_nominal_model_mm_deg"] = rms(nominal)
        out["held_out_poses"] = len(held_out)
    t, i = truth.intrinsics, result.intrinsics
    out["intrinsics_error_px"] = {"fu": round(i.fu - t.fu, 3), "fv": round(i.fv - t.fv, 3), "cx": round(i.cx - t.cx, 3), "cy": round(i.cy - t.cy, 3)}
    return out
