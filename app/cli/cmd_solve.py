"""``videocal solve IN.json``: solve a camera pose from point pairs, print the result as JSON.

Exit codes: 0 solved (``ok`` or ``ambiguous``), 2 bad input (one ``error:`` line),
3 the solve failed (the JSON is still printed, with the reason).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.documents import read_json
from calib_core.errors import FileFormatError
from calib_core.frames import make_transform
from calib_core.solver import SolveStatus, solve_pose

EXIT_FAILED = 3
_KNOWN_FIELDS = {"intrinsics", "points_3d", "points_2d", "prior", "estimate_focal", "model", "sigma_px", "robust"}
_INTRINSICS_FIELDS = {"fu", "fv", "cx", "cy", "width", "height", "distortion"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", type=Path, help="JSON file: intrinsics, points_3d (mm), points_2d (px), options")
    parser.add_argument("--indent", type=int, default=2, help="JSON indentation (0 for one line)")


def _field(data: dict, name: str, path: Path):
    if name not in data:
        raise FileFormatError(path, "required field is missing", name)
    return data[name]


def _intrinsics(data: dict, path: Path) -> Intrinsics:
    raw = _field(data, "intrinsics", path)
    if not isinstance(raw, dict):
        raise FileFormatError(path, "must be an object with fu, fv, cx, cy, width, height", "intrinsics")
    unknown = set(raw) - _INTRINSICS_FIELDS
    if unknown:
        raise FileFormatError(path, f"unknown field(s) {', '.join(sorted(unknown))}", "intrinsics")
    for key in ("fu", "fv", "cx", "cy", "width", "height"):
        if key not in raw:
            raise FileFormatError(path, "required field is missing", f"intrinsics.{key}")
        value = raw[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise FileFormatError(path, f"must be a number, got {value!r}", f"intrinsics.{key}")
    try:
        return Intrinsics(raw["fu"], raw["fv"], raw["cx"], raw["cy"], raw["width"], raw["height"], tuple(raw.get("distortion", (0.0,) * 5)))
    except (TypeError, ValueError) as exc:
        raise FileFormatError(path, str(exc), "intrinsics") from None


def _prior(data: dict, path: Path) -> np.ndarray | None:
    raw = data.get("prior")
    if raw is None:
        return None
    try:
        R = np.asarray(raw["R_obj2cam"], dtype=float).reshape(3, 3)
        t = np.asarray(raw["t_obj2cam_mm"], dtype=float).reshape(3)
    except (KeyError, TypeError, ValueError) as exc:
        raise FileFormatError(path, f"needs R_obj2cam (3x3) and t_obj2cam_mm (3 numbers): {exc}", "prior") from None
    return make_transform(R, t)


def _option(data: dict, name: str, kind, default, path: Path):
    value = data.get(name, default)
    if value is None or value is default:
        return value
    if kind is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if kind is bool and isinstance(value, bool):
        return value
    if kind is str and isinstance(value, str):
        return value
    raise FileFormatError(path, f"must be a {kind.__name__}, got {value!r}", name)


def run(args: argparse.Namespace) -> int:
    path: Path = args.input
    data = read_json(path, "solve input file")
    if not isinstance(data, dict):
        raise FileFormatError(path, "the top level must be a JSON object")
    unknown = set(data) - _KNOWN_FIELDS
    if unknown:
        raise FileFormatError(path, f"unknown field(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_KNOWN_FIELDS))}")
    solution = solve_pose(
        _field(data, "points_3d", path),
        _field(data, "points_2d", path),
        _intrinsics(data, path),
        prior=_prior(data, path),
        estimate_focal=_option(data, "estimate_focal", bool, False, path),
        model=_option(data, "model", str, "pinhole", path),
        sigma_px=_option(data, "sigma_px", float, None, path),
        robust=_option(data, "robust", bool, False, path),
    )
    json.dump(solution.to_dict(), sys.stdout, indent=args.indent or None)
    sys.stdout.write("\n")
    return EXIT_FAILED if solution.status is SolveStatus.FAILED else 0
