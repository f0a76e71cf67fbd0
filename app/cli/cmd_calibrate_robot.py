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


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("source", choices=("sim",), help="'sim': the cold cell of the simulated test bed")
    parser.add_argument("--views", type=bounded_int(8, 200), default=40, help="poses to view the board from (8 to 200)")
    parser.add_argument("--with-intrinsics", action="store_true", help="refine the camera's intrinsics with the robot (they are calibrated from the same views first either way)")
    parser.add_argument("--seed", type=bounded_int(0, 10_000), default=0, help="which cold cell (its errors are drawn from this)")
    parser.add_argument("--out", type=Path, required=True, help="folder for robot_calibration.yaml and the calibrated URDF")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    from calib_core.testbed.cold_robot_calibration import calibrate_cold_cell
    from calib_core.robot_calibration.report import save_robot_calibration

    def progress(k, n):
        print(f"\rview {k} of {n}", end="" if k < n else "\n", file=sys.stderr)

    run_ = calibrate_cold_cell(args.views, args.seed, with_intrinsics=args.with_intrinsics, progress=progress, say=lambda text: print(text, file=sys.stderr))
    for r in run_.rejected:
        print(f"rejected {r}", file=sys.stderr)
    result = run_.result
    args.out.mkdir(parents=True, exist_ok=True)
    save_robot_calibration(args.out, result, run_.nominal_robot)
    summary = {"views": len(result.per_view_rms_px), "rejected": run_.rejected, "rms_px": result.rms_px, "start_rms_px": result.start_rms_px, "seconds": result.seconds,
               "identified": len(result.observability.identified), "of": len(result.names), "condition": result.observability.condition,
               "intrinsics_rms_px": run_.intrinsics.rms_px, "score": run_.score, "out": str(args.out)}
    if args.json:
        json.dump(summary, sys.stdout, indent=2, default=float)
        sys.stdout.write("\n")
        return 0
    print(f"{summary['views']} views; RMS {result.start_rms_px:.2f} px with the nominal model -> {result.rms_px:.3f} px; {summary['identified']} of {summary['of']} parameters identified (condition {result.observability.condition:.0f}) in {result.seconds:.1f} s")
    for key, value in run_.score.items():
        print(f"  {key}: {value}")
    print(f"wrote {args.out}")
    return 0
