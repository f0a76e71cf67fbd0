"""The workspace file (JSON, ``schema_version`` 2): the workcell in use and its identity (name and
content hash: a workspace opens only on its own cell), the intrinsics, the task locations, the
point pairs and the correction table with its history. Version 1 files (no identity) still open.

Saving is atomic (a crash mid-save leaves the old file intact). Loading is strict: a corrupt,
truncated, unknown-version or foreign file gives a :class:`FileFormatError` naming the file and
the field. Files are data only: nothing in them is executed.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from calib_core import __version__
from calib_core.atomic_file import atomic_write_text
from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.calibration.correspondences import Correspondence, pair_to_dict
from calib_core.calibration.verification import Verification
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.camera.intrinsics import Intrinsics
from calib_core.documents import read_json
from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.workcell.model import TaskLocation
from calib_core.names import name_problem, note_problem
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM

SCHEMA_VERSION = 2
_READABLE_VERSIONS = (1, 2)
KIND = "videocal-workspace"


@dataclass
class Workspace:
    """Everything an operator's work needs to be resumed, reviewed or exported."""

    workcell_path: str
    intrinsics: Intrinsics
    task_locations: dict[str, TaskLocation] = field(default_factory=dict)
    target: str | None = None
    pairs: list[Correspondence] = field(default_factory=list)
    corrections: CorrectionTable = field(default_factory=CorrectionTable)
    created_s: float = field(default_factory=time.time)
    cell: dict | None = None
    """``{"name", "content_hash"}`` of the cell it was made on (:class:`~calib_core.operator.cell.CellIdentity`)."""


def _pose(T: np.ndarray) -> dict:
    xyz, rpy = xyz_rpy_from_transform(T)
    return {"xyz": [float(v) for v in xyz], "rpy": [float(v) for v in rpy]}


def _correction_dict(c: Correction) -> dict:
    return {
        "task": c.task,
        "time_s": c.time_s,
        "source": c.source,
        "joints_deg": c.joints_deg.tolist(),
        "tcp2base_model": _pose(c.tcp2base_model),
        "tcp2base_measured": _pose(c.tcp2base_measured),
        "displacement_mm": c.displacement_mm.tolist(),
        "rotation_deg": c.rotation_deg.tolist(),
        "std_displacement_mm": c.std_displacement_mm.tolist(),
        "std_rotation_deg": c.std_rotation_deg.tolist(),
        "rms_px": c.rms_px,
        "pairs": c.pairs,
        "verdict": c.verdict,
        "confirmation": c.confirmation,
        "kind": c.kind,
    }


def workspace_to_dict(ws: Workspace) -> dict:
    return {
        "kind": KIND,
        "schema_version": SCHEMA_VERSION,
        "videocal_version": __version__,
        "created_s": ws.created_s,
        "saved_s": time.time(),
        "workcell": ws.workcell_path,
        "cell": ws.cell,
        "intrinsics": ws.intrinsics.to_dict(),
        "target": ws.target,
        "task_locations": [
            {
                "name": t.name,
                "component": t.component,
                "approach_mm": t.approach_mm,
                "tolerance_mm": t.tolerance_mm,
                "tcp2base": _pose(t.tcp2base),
            }
            for t in ws.task_locations.values()
        ],
        "pairs": [pair_to_dict(p) for p in ws.pairs],
        "corrections": [_correction_dict(c) for task in ws.corrections.tasks() for c in ws.corrections.history(task)],
        "verifications": [
            _verification_dict(v) for task in ws.corrections.tasks() for v in ws.corrections.verifications(task)
        ],
    }


def _verification_dict(v: Verification) -> dict:
    return {
        "task": v.task,
        "time_s": v.time_s,
        "remaining_mm": v.remaining_mm.tolist(),
        "remaining_deg": v.remaining_deg.tolist(),
        "std_remaining_mm": v.std_remaining_mm.tolist(),
        "disagreement_mm": v.disagreement_mm,
        "agree_within_mm": v.agree_within_mm,
        "rms_px": v.rms_px,
        "pairs": v.pairs,
        "tolerance_mm": v.tolerance_mm,
    }


def _correction_kind(value, field: str, f) -> str:
    if value not in ("correction", "measurement"):
        raise f.fail(field, f"must be 'correction' or 'measurement', got {value!r}")
    return value


def save_workspace(path: str | Path, ws: Workspace) -> None:
    """Write atomically: the old file stays whole until the new one is complete on disk."""
    atomic_write_text(path, json.dumps(workspace_to_dict(ws), indent=1))


MAX_MAGNITUDE = 1e7
"""The largest coordinate a workspace may hold (mm, px): 10 km."""
MAX_SIGMA = 1e6
"""The largest 1-sigma a workspace may hold (mm, deg): a 1 km uncertainty is no measurement."""


class _Fields:
    def __init__(self, path: Path):
        self.path = path

    def fail(self, field: str | None, message: str) -> FileFormatError:
        return FileFormatError(self.path, message, field)

    def get(self, data: dict, key: str, where: str, kind=None):
        if not isinstance(data, dict):
            raise self.fail(where or None, "must be an object")
        if key not in data:
            raise self.fail(f"{where}.{key}" if where else key, "missing")
        value = data[key]
        if kind is not None and not isinstance(value, kind):
            raise self.fail(
                f"{where}.{key}" if where else key,
                f"must be {getattr(kind, '__name__', kind)}, got {type(value).__name__}",
            )
        return value

    def name(self, data: dict, key: str, where: str) -> str:
        """A name (task location, component, feature): text without control characters."""
        value = self.get(data, key, where, str)
        why = name_problem(value)
        if why is not None:
            raise self.fail(f"{where}.{key}" if where else key, f"the name {value[:60]!r} {why}")
        return value

    def note(self, data: dict, key: str, where: str) -> str:
        """A line of text (a correction's source, who confirmed it), empty when absent: written into exports as a
        remark, so one line without control characters (a newline there would start a controller's statement)."""
        value = data.get(key, "")
        why = note_problem(value)
        if why is not None:
            shown = value[:60] if isinstance(value, str) else value
            raise self.fail(f"{where}.{key}", f"the text {shown!r} {why}")
        return value

    def verdict(self, data: dict, where: str) -> str:
        """A correction's verdict: one of the verdicts' words (default ``ok``)."""
        from calib_core.calibration.verdict import Verdict

        value = data.get("verdict", "ok")
        words = [v.value for v in Verdict]
        if value not in words:
            raise self.fail(f"{where}.verdict", f"must be one of {', '.join(words)}, got {value!r}")
        return value

    def vector(self, value, n: int, where: str, bound: float = MAX_MAGNITUDE) -> np.ndarray:
        """``n`` finite numbers, each at most ``bound`` in size (mm, px: a cell is metres across, an image thousands
        of pixels; -1e308 is a damaged file, and an export would carry it to a controller)."""
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise self.fail(where, f"must be {n} finite numbers, got {value!r}") from None
        if arr.shape != (n,) or not np.all(np.isfinite(arr)):
            raise self.fail(where, f"must be {n} finite numbers, got {value!r}")
        if np.abs(arr).max() > bound:
            raise self.fail(where, f"must be {n} numbers within +-{bound:g}, got {value!r}")
        return arr

    def sigmas(self, value, n: int, where: str) -> np.ndarray:
        """``n`` 1-sigma values: non-negative numbers, or null / NaN for one that is not known."""
        if (
            not isinstance(value, list)
            or len(value) != n
            or not all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in value)
        ):
            raise self.fail(where, f"must be {n} numbers (null for an unknown one), got {value!r}")
        arr = np.array([np.nan if v is None else v for v in value], dtype=float)
        if np.any(arr < 0) or np.any(np.isinf(arr)) or np.any(arr > MAX_SIGMA):
            raise self.fail(where, f"must be {n} non-negative finite numbers up to {MAX_SIGMA:g}, got {value!r}")
        return arr

    def number(self, value, where: str, low: float = -np.inf, high: float = np.inf, allow_nan: bool = False) -> float:
        bounds = "" if low == -np.inf and high == np.inf else f" from {low:g} to {high:g}"
        try:
            v = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None
        except OverflowError:  # an integer past any float
            v = None
        if v is None or (math.isnan(v) and not allow_nan) or math.isinf(v) or not (math.isnan(v) or low <= v <= high):
            raise self.fail(where, f"must be a finite number{bounds}, got {value!r}")
        return v

    def joints(self, value, where: str) -> np.ndarray:
        """A joint vector of any robot: 1 to 16 finite numbers (deg or mm)."""
        n = len(value) if isinstance(value, list) else -1
        if not 1 <= n <= 16:
            raise self.fail(where, f"must be a list of 1 to 16 joint values (deg or mm), got {value!r}")
        return self.vector(value, n, where)

    def pose(self, value, where: str) -> np.ndarray:
        return transform_from_xyz_rpy(
            self.vector(self.get(value, "xyz", where), 3, f"{where}.xyz"),
            self.vector(self.get(value, "rpy", where), 3, f"{where}.rpy"),
        )


def _tolerance(f, t: dict, where: str) -> float:
    value = f.number(t.get("tolerance_mm", DEFAULT_TOLERANCE_MM), f"{where}.tolerance_mm", 0.0, 1e6)
    if value <= 0:
        raise f.fail(f"{where}.tolerance_mm", f"must be a number > 0 (mm), got {value!r}")
    return value


def load_workspace(path: str | Path) -> Workspace:
    path = Path(path)
    f = _Fields(path)
    data = read_json(path, "workspace file", max_bytes=64 * 1024 * 1024)  # size and nesting bounded first
    if not isinstance(data, dict) or data.get("kind") != KIND:
        raise f.fail("kind", f"not a videocal workspace (kind must be {KIND!r})")
    version = data.get("schema_version")
    if version not in _READABLE_VERSIONS:
        raise f.fail(
            "schema_version",
            f"this videocal reads versions {', '.join(map(str, _READABLE_VERSIONS))}, the file is version {version!r}",
        )
    cell = data.get("cell")
    if cell is not None and not (
        isinstance(cell, dict) and isinstance(cell.get("name"), str) and isinstance(cell.get("content_hash"), str)
    ):
        raise f.fail("cell", f"must be {{name, content_hash}} strings, got {cell!r}")
    try:
        intrinsics = Intrinsics.from_dict(f.get(data, "intrinsics", "", dict))
    except (KeyError, TypeError, ValueError) as exc:
        raise f.fail("intrinsics", str(exc)) from None
    tasks = {}
    for i, t in enumerate(f.get(data, "task_locations", "", list)):
        where = f"task_locations[{i}]"
        name = f.name(t, "name", where)
        component = t.get("component")
        if component is not None and not isinstance(component, str):
            raise f.fail(f"{where}.component", f"must be the name of one component, got {component!r}")
        approach = f.number(f.get(t, "approach_mm", where), f"{where}.approach_mm", 0.0, 10000.0)
        tasks[name] = TaskLocation(
            name,
            f.pose(f.get(t, "tcp2base", where, dict), f"{where}.tcp2base"),
            approach,
            component,
            _tolerance(f, t, where),
        )
    pairs = []
    for i, p in enumerate(f.get(data, "pairs", "", list)):
        where = f"pairs[{i}]"
        pixel = p.get("pixel") if isinstance(p, dict) else None
        view = None
        if pixel is not None and p.get("view") is not None:
            try:
                view = ViewStamp.from_dict(p["view"])
            except (KeyError, TypeError, ValueError) as exc:
                raise f.fail(f"{where}.view", f"not a frame stamp: {exc}") from None
        pairs.append(
            Correspondence(
                int(f.get(p, "number", where, int)),
                f.name(p, "component", where),
                None if p.get("feature") is None else f.name(p, "feature", where),
                tuple(f.vector(f.get(p, "point_world_mm", where), 3, f"{where}.point_world_mm")),
                None if pixel is None else tuple(f.vector(pixel, 2, f"{where}.pixel")),
                bool(p.get("enabled", True)),
                view,
            )
        )
    table = CorrectionTable()
    for i, c in enumerate(f.get(data, "corrections", "", list)):
        where = f"corrections[{i}]"
        table.add(
            Correction(
                task=f.name(c, "task", where),
                tcp2base_model=f.pose(f.get(c, "tcp2base_model", where, dict), f"{where}.tcp2base_model"),
                tcp2base_measured=f.pose(f.get(c, "tcp2base_measured", where, dict), f"{where}.tcp2base_measured"),
                displacement_mm=f.vector(f.get(c, "displacement_mm", where), 3, f"{where}.displacement_mm"),
                rotation_deg=f.vector(f.get(c, "rotation_deg", where), 3, f"{where}.rotation_deg"),
                std_displacement_mm=f.sigmas(f.get(c, "std_displacement_mm", where), 3, f"{where}.std_displacement_mm"),
                std_rotation_deg=f.sigmas(f.get(c, "std_rotation_deg", where), 3, f"{where}.std_rotation_deg"),
                joints_deg=f.joints(f.get(c, "joints_deg", where), f"{where}.joints_deg"),
                rms_px=f.number(f.get(c, "rms_px", where), f"{where}.rms_px", 0.0, 1e6, allow_nan=True),
                pairs=int(f.get(c, "pairs", where, int)),
                time_s=f.number(c.get("time_s", 0.0), f"{where}.time_s"),
                source=f.note(c, "source", where),
                verdict=f.verdict(c, where),
                confirmation=f.note(c, "confirmation", where),
                kind=_correction_kind(c.get("kind", "correction"), f"{where}.kind", f),
            )
        )
    verifications = data.get("verifications", []) or []
    if not isinstance(verifications, list):
        raise f.fail("verifications", f"must be a list, got {type(verifications).__name__}")
    for i, v in enumerate(verifications):
        where = f"verifications[{i}]"
        try:
            table.add_verification(
                Verification(
                    str(v["task"]),
                    np.asarray(v["remaining_mm"], float).reshape(3),
                    np.asarray(v["remaining_deg"], float).reshape(3),
                    np.asarray(v["std_remaining_mm"], float).reshape(3),
                    float(v["disagreement_mm"]),
                    float(v["agree_within_mm"]),
                    float(v["rms_px"]),
                    int(v["pairs"]),
                    float(v.get("time_s", 0.0)),
                    float(v.get("tolerance_mm", DEFAULT_TOLERANCE_MM)),
                )
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise f.fail(where, f"not a verification: {exc}") from None
    target = data.get("target")
    if target is not None and not isinstance(target, str):
        raise f.fail("target", f"must be the name of one component, got {target!r}")
    return Workspace(
        str(f.get(data, "workcell", "", str)),
        intrinsics,
        tasks,
        target,
        pairs,
        table,
        f.number(data.get("created_s", 0.0), "created_s"),
        cell,
    )
