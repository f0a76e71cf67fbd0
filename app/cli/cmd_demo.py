"""``videocal demo``: the whole calibration driven through the real window, with a PNG after
each step and ``report.json`` in the output folder."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from app.cli.options import bounded_float
from calib_core.errors import VideocalError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("out/demo"), help="folder for the screenshots and report.json")
    parser.add_argument("--offscreen", action="store_true", help="no display needed: Qt's offscreen platform")
    parser.add_argument("--scale", type=bounded_float(0.1, 2.0), default=1.0, help="camera resolution relative to the camera file's")
    parser.add_argument("--workcell", type=Path, default=None, help="the cell to calibrate in (default: the bundled one)")
    parser.add_argument("--location", help="the task location to calibrate at (default: the cell's first)")
    parser.add_argument("--method", choices=("picks", "find-points", "edges"), default="picks",
                        help="how each look is made: the operator's picks (default), Find points and Accept all, or Find points and Calibrate on edges")


def run(args: argparse.Namespace) -> int:
    if args.out.exists() and not args.out.is_dir():
        raise VideocalError(f"{args.out}: --out names a file; the demo writes its screenshots and report.json into a folder")
    if args.offscreen:
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from app.gui.demo import run_demo

    from calib_core.workcell import DEFAULT_WORKCELL

    report = run_demo(args.out, scale=args.scale, workcell=args.workcell or DEFAULT_WORKCELL, location=args.location, method=args.method)
    print(json.dumps({k: report[k] for k in ("status", "pairs", "rms_px", "corrected_tcp_error_mm", "corrected_tcp_error_deg", "uncorrected_tcp_error_mm")}, indent=2))
    print(f"screenshots and report.json in {args.out}")
    return 0
