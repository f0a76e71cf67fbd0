"""``videocal replay FILE``: re-solve every calibration in a recording and compare.

Exit 0 when every re-computed result agrees with the recorded one (exactly, or to round-off: a newer solver reaching the
same minimum), 5 when any differs,
2 for a file that cannot be read (one ``error:`` line).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

EXIT_DIFFERS = 5


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recording", type=Path, help="a videocal MCAP recording")
    parser.add_argument("--json", action="store_true", help="print one JSON document")


def run(args: argparse.Namespace) -> int:
    from calib_core.recording.reader import read_recording
    from calib_core.recording.replay import replay

    contents = read_recording(args.recording)
    if not contents.complete:
        print(
            f"warning: {args.recording}: {contents.problem}; replaying what is there (videocal recover rewrites it)",
            file=sys.stderr,
        )
    results = replay(args.recording)
    if args.json:
        json.dump(
            {
                "recording": str(args.recording),
                "complete": contents.complete,
                "solves": [
                    {
                        "id": r.id,
                        "agree": r.agree,
                        "equivalent": r.equivalent,
                        "skipped": r.skipped,
                        "recorded_status": r.recorded["status"],
                        "recomputed_status": r.recomputed["status"],
                        "translation_diff_mm": r.translation_diff_mm,
                        "rotation_diff": r.rotation_diff,
                        "rms_diff_px": r.rms_diff_px,
                        "recorded": {"t_obj2cam_mm": r.recorded["t_obj2cam_mm"], "rms_px": r.recorded["rms_px"]},
                        "recomputed": {"t_obj2cam_mm": r.recomputed["t_obj2cam_mm"], "rms_px": r.recomputed["rms_px"]},
                    }
                    for r in results
                ],
            },
            sys.stdout,
            indent=2,
        )
        sys.stdout.write("\n")
    else:
        print(f"{args.recording}: {len(results)} solves")
        for r in results:
            if r.skipped:
                verdict = f"skipped ({r.skipped})"
            elif r.agree:
                verdict = "agrees"
            elif r.equivalent:
                verdict = (
                    f"agrees to round-off ({r.translation_diff_mm:.1g} mm: not bit for bit, another solver version)"
                )
            else:
                verdict = (
                    f"DIFFERS (translation {r.translation_diff_mm:.3g} mm, rotation {r.rotation_diff:.3g}, rms "
                    f"{r.rms_diff_px:.3g} px)"
                )
            rms = "n/a" if r.recorded["rms_px"] is None else f"{r.recorded['rms_px']:.3f} px"
            print(
                f"  solve {r.id}: recorded {r.recorded['status']} rms {rms}, re-computed {r.recomputed['status']}: "
                f"{verdict}"
            )
    return 0 if all(r.equivalent for r in results) else EXIT_DIFFERS
