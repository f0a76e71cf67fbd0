"""``videocal recover FILE [--out OUT]``: rewrite a recording cut off by a crash as a complete file
with every message before the cut (default output: FILE with ``.recovered.mcap``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from calib_core.errors import VideocalError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", type=Path)
    parser.add_argument("--out", type=Path, help="where to write the recovered recording")


def run(args: argparse.Namespace) -> int:
    from calib_core.recording.reader import recover

    out = args.out or args.recording.with_suffix(".recovered.mcap")
    if out.resolve() == args.recording.resolve():
        raise VideocalError("--out must differ from the recording: the original is never overwritten")
    contents = recover(args.recording, out)
    state = "was complete" if contents.complete else f"was cut off: {contents.problem}"
    print(f"{args.recording} {state}; {len(contents.messages)} messages written to {out}")
    return 0
