"""``videocal table1``: reproduce the paper's Table 1 (Newton's method from ten displaced starts).

Prints each test's initial displacement, the final error reached here and the paper's
figure, as a table or (``--json``) as one JSON document. Exit 0 when every test converges.
"""

from __future__ import annotations

import argparse
import json
import sys


_COLUMNS = ("d_x", "d_y", "d_z", "phi_x", "phi_y", "phi_z")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument(
        "--model",
        choices=("pinhole", "paper"),
        default="pinhole",
        help="camera model (default: pinhole; paper = the paper's own equations)",
    )
    parser.add_argument(
        "--as-printed",
        action="store_true",
        help="use the paper's derivatives exactly as printed (with their two misprints) and undamped Newton steps",
    )


def _format_row(label: str, values) -> str:
    return f"{label:<10}" + "".join(
        f"{v:>11.2e}" if isinstance(v, float) and v != 0 and abs(v) < 1e-2 else f"{v:>11.4g}" for v in values
    )


def run(args: argparse.Namespace) -> int:
    from calib_core.solver.paper_table1 import run_table1  # the solver's kernels load with it: not for --help

    if args.as_printed and args.model != "paper":
        raise ValueError("--as-printed applies to the paper's model: add --model paper")
    rows = run_table1(args.model, as_printed=args.as_printed)
    if args.json:
        json.dump(
            {
                "model": args.model,
                "as_printed": args.as_printed,
                "units": {"d_x": "mm", "d_y": "mm", "d_z": "mm", "phi_x": "deg", "phi_y": "deg", "phi_z": "deg"},
                "tests": [
                    {
                        "test": r.test,
                        "start": dict(zip(_COLUMNS, r.start)),
                        "final_error": dict(zip(_COLUMNS, r.final_error)),
                        "paper_final_error": dict(zip(_COLUMNS, r.paper)),
                        "iterations": r.iterations,
                        "converged": r.converged,
                        "outcome": r.outcome,
                    }
                    for r in rows
                ],
            },
            sys.stdout,
            indent=2,
        )
        sys.stdout.write("\n")
    else:
        title = (
            "the paper's model" + (" as printed (misprinted derivatives, undamped)" if args.as_printed else "")
            if args.model == "paper"
            else "pinhole model"
        )
        print(
            f"Table 1 of the paper, re-run with the {title}: initial displacement, final error here, paper's final "
            "error"
        )
        print(
            f"{'':<10}"
            + "".join(f"{c + (' mm' if c.startswith('d') else ' deg'):>11}" for c in _COLUMNS)
            + "   iterations"
        )
        for r in rows:
            print(_format_row(f"#{r.test} start", r.start))
            print(
                _format_row("  here", r.final_error)
                + f"   {r.iterations}"
                + ("" if r.converged else f"  ({r.outcome})")
            )
            print(_format_row("  paper", r.paper))
        worst_t = max(r.max_translation_error for r in rows)
        worst_r = max(r.max_rotation_error_deg for r in rows)
        print(
            f"largest final error here: {worst_t:.2e} mm, {worst_r:.2e} deg; {sum(r.converged for r in rows)} of "
            f"{len(rows)} converged"
        )
    return 0 if all(r.converged for r in rows) else 1
