"""``videocal export WORKSPACE --format F [--out FILE]``: the corrected task locations for a robot
controller (URScript, RAPID, KRL, FANUC TP, PDL2) or a spreadsheet (CSV, JSON); stdout without ``--out``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from calib_core.workspace.exports import EXPORT_FORMATS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("workspace", type=Path)
    parser.add_argument("--format", choices=EXPORT_FORMATS, default="csv",
                        help="csv, json (every correction, with the target to command), or a controller listing: urscript (UR), rapid (ABB), krl (KUKA), fanuc (FANUC TP), pdl2 (COMAU)")
    parser.add_argument("--out", type=Path)


def run(args: argparse.Namespace) -> int:
    from calib_core.atomic_file import atomic_write_text
    from calib_core.workspace.exports import export_corrections
    from calib_core.workspace.workspace import load_workspace

    ws = load_workspace(args.workspace)
    text = export_corrections(args.format, ws.corrections, ws.task_locations, args.out.name.split(".")[0] if args.out else None)
    if args.out:
        atomic_write_text(args.out, text)
        print(f"wrote {args.out}")
    else:
        sys.stdout.write(text)
    return 0
