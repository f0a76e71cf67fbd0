"""``videocal calibrate-robot sim --out DIR``: the robot's geometric parameters and its camera
mounting from views of a board at many poses (docs/calibration.md).

``sim`` runs it on the cold cell (calib_core/testbed/cold_cell.py): the poses planned, the robot
driven through them, each view rendered by the true camera and detected; the camera's intrinsics
calibrated from the same views first; the result scored against the truth, which nothing else reads.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


from app.cli.options import bounded_int

HELD_OUT = 20
"""Planned poses not used for the calibration: the truth is compared there."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source", choices=("sim",), help="'sim': the cold cell of the simulated test bed")
    parser.add_argument("--views", type=bounded_int(8, 200), default=40, help="poses to view the board from (8 to 200)")
    parser.add_argument("--with-intrinsics", action="store_true", help="refine the camera's intrinsics with the robot (they are calibrated from the same views first either way)")
    parser.add_argument("--seed", type=bounded_int(0, 10_000), default=0, help="which cold cell (its errors are drawn from this)")
    parser.add_argument("--out", type=Path, required=True, help="folder for robot_calibration.yaml and the calibrated URDF")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.robot_calibration.identification import identify
    from calib_core.robot_calibration.pose_planner import plan_poses
    from calib_core.robot_calibration.report import save_robot_calibration, score_against_truth
    from calib_core.robot_calibration.sim_views import simulated_pose_views
    from calib_core.testbed.cold_cell import cold_test_bed
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.board_placement import board_in_cell
    from calib_core.vision.intrinsics_calibration import calibrate_intrinsics

    bed, truth = cold_test_bed(seed=args.seed)
    nominal = load_intrinsics(bed.workcell.intrinsics_path)
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, bed.workcell, bed.model_robot)
    print(f"planning {args.views} poses...", file=sys.stderr)
    wanted = args.views + HELD_OUT
    plan = plan_poses(bed.model_robot, nominal, spec, board2base, wanted, start_deg=bed.workcell.home_joints_deg, candidates=min(160, 3 * wanted), seed=args.seed)
    calibration_q, held_out = plan.joints_deg[: args.views], plan.joints_deg[args.views:]

    def progress(k, n):
        print(f"\rview {k} of {n}", end="" if k < n else "\n", file=sys.stderr)

    board_views, views, rejected = simulated_pose_views(bed, spec, board2base, calibration_q, seed=args.seed, progress=progress)
    for r in rejected:
        print(f"rejected {r}", file=sys.stderr)
    intrinsics = calibrate_intrinsics(board_views, spec)
    print(f"intrinsics: RMS {intrinsics.rms_px:.3f} px from {len(board_views)} views; identifying...", file=sys.stderr)
    result = identify(bed.model_robot, intrinsics.intrinsics, views, with_intrinsics=args.with_intrinsics)
    args.out.mkdir(parents=True, exist_ok=True)
    save_robot_calibration(args.out, result, bed.model_robot)
    score = score_against_truth(result, bed, truth, held_out, board2base)
    summary = {"views": len(views), "rejected": rejected, "rms_px": result.rms_px, "start_rms_px": result.start_rms_px, "seconds": result.seconds,
               "identified": len(result.observability.identified), "of": len(result.names), "condition": result.observability.condition,
               "intrinsics_rms_px": intrinsics.rms_px, "score": score, "out": str(args.out)}
    if args.json:
        json.dump(summary, sys.stdout, indent=2, default=float)
        sys.stdout.write("\n")
        return 0
    print(f"{len(views)} views; RMS {result.start_rms_px:.2f} px with the nominal model -> {result.rms_px:.3f} px; {len(result.observability.identified)} of {len(result.names)} parameters identified (condition {result.observability.condition:.0f}) in {result.seconds:.1f} s")
    for key, value in score.items():
        print(f"  {key}: {value}")
    print(f"wrote {args.out}")
    return 0
