"""``videocal export WORKSPACE --format json|csv|pdl2 [--out FILE]``: the correction table for the
controller or a spreadsheet (stdout without ``--out``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("workspace", type=Path)
    parser.add_argument("--format", choices=("json", "csv", "pdl2"), default="csv")
    parser.add_argument("--out", type=Path)


def run(args: argparse.Namespace) -> int:
    from calib_core.atomic_file import atomic_write_text
    from calib_core.workspace.exports import corrections_csv, corrections_json, corrections_pdl2
    from calib_core.workspace.workspace import load_workspace

    ws = load_workspace(args.workspace)
    text = {"json": lambda: corrections_json(ws.corrections), "csv": lambda: corrections_csv(ws.corrections), "pdl2": lambda: corrections_pdl2(ws.corrections, ws.task_locations)}[args.format]()
    if args.out:
        atomic_write_text(args.out, text)
        print(f"wrote {args.out}")
    else:
        sys.stdout.write(text)
    return 0
