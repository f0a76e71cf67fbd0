"""``videocal demo``: the whole calibration driven through the real window, with a PNG after
each step and ``report.json`` in the output folder."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("out/demo"), help="folder for the screenshots and report.json")
    parser.add_argument("--offscreen", action="store_true", help="no display needed: Qt's offscreen platform")
    parser.add_argument("--scale", type=float, default=1.0, help="camera resolution relative to 1280 x 960")


def run(args: argparse.Namespace) -> int:
    if args.offscreen:
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from app.gui.demo import run_demo

    report = run_demo(args.out, scale=args.scale)
    print(json.dumps({k: report[k] for k in ("status", "pairs", "rms_px", "corrected_tcp_error_mm", "corrected_tcp_error_deg", "uncorrected_tcp_error_mm")}, indent=2))
    print(f"screenshots and report.json in {args.out}")
    return 0
