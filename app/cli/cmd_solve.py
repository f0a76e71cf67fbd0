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

from calib_core.documents import read_json
from calib_core.errors import FileFormatError

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


def _points(data: dict, name: str, dim: int, path: Path) -> np.ndarray:
    raw = _field(data, name, path)
    if not isinstance(raw, list) or not all(
        isinstance(p, list)
        and len(p) == dim
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in p)
        for p in raw
    ):
        raise FileFormatError(path, f"must be a list of [{', '.join('xyz'[:dim] if dim == 3 else 'uv')}] numbers", name)
    points = np.array(raw, dtype=float).reshape(len(raw), dim)
    if not np.all(np.isfinite(points)):
        raise FileFormatError(path, "contains NaN or infinite values", name)
    return points


def _intrinsics(data: dict, path: Path):
    """The ``intrinsics`` field as an :class:`~calib_core.camera.intrinsics.Intrinsics`."""
    from calib_core.camera.intrinsics import Intrinsics  # (with the camera package, scipy: not for --help)

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
        return Intrinsics(
            raw["fu"],
            raw["fv"],
            raw["cx"],
            raw["cy"],
            raw["width"],
            raw["height"],
            tuple(raw.get("distortion", (0.0,) * 5)),
        )
    except (TypeError, ValueError) as exc:
        raise FileFormatError(path, str(exc), "intrinsics") from None


def _prior(data: dict, path: Path) -> np.ndarray | None:
    from calib_core.frames import make_transform  # (scipy: not for --help)

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


MAX_POINTS = 10_000


def read_solve_inputs(path: Path) -> dict:
    """The arguments of :func:`~calib_core.solver.solve_pose` from a solve input file, every field
    checked; ``FileFormatError`` names the file and the field."""
    data = read_json(path, "solve input file")
    if not isinstance(data, dict):
        raise FileFormatError(path, "the top level must be a JSON object")
    unknown = set(data) - _KNOWN_FIELDS
    if unknown:
        raise FileFormatError(
            path, f"unknown field(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_KNOWN_FIELDS))}"
        )
    for name in ("points_3d", "points_2d"):
        if isinstance(data.get(name), list) and len(data[name]) > MAX_POINTS:
            raise FileFormatError(path, f"{len(data[name])} points; a solve takes at most {MAX_POINTS}", name)
    return {
        "points_3d": _points(data, "points_3d", 3, path),
        "points_2d": _points(data, "points_2d", 2, path),
        "intrinsics": _intrinsics(data, path),
        "prior": _prior(data, path),
        "estimate_focal": _option(data, "estimate_focal", bool, False, path),
        "model": _option(data, "model", str, "pinhole", path),
        "sigma_px": _option(data, "sigma_px", float, None, path),
        "robust": _option(data, "robust", bool, False, path),
    }


def run(args: argparse.Namespace) -> int:
    from calib_core.solver import SolveStatus, solve_pose  # the solver's kernels load with it: not for --help

    inputs = read_solve_inputs(args.input)
    solution = solve_pose(inputs.pop("points_3d"), inputs.pop("points_2d"), inputs.pop("intrinsics"), **inputs)
    json.dump(solution.to_dict(), sys.stdout, indent=args.indent or None)
    sys.stdout.write("\n")
    return EXIT_FAILED if solution.status is SolveStatus.FAILED else 0
