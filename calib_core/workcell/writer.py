"""Saving an edited cell back to its workcell YAML without losing what the file says otherwise:
the file is read and written with ruamel.yaml's round trip, so comments, key order and the
entries videocal did not touch stay as they were; components and task locations are updated in
place or appended, and the file is replaced atomically.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
from ruamel.yaml import YAML
from ruamel.yaml.comments import CommentedMap, CommentedSeq

from calib_core.atomic_file import atomic_write_text
from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.workcell.model import Workcell
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM

_DECIMALS = 4


def _flow(values) -> CommentedSeq:
    seq = CommentedSeq([float(round(float(v), _DECIMALS)) for v in values])
    seq.fa.set_flow_style()
    return seq


def _placement(T: np.ndarray) -> CommentedMap:
    xyz, rpy = xyz_rpy_from_transform(T)
    m = CommentedMap([("xyz", _flow(xyz)), ("rpy", _flow(rpy))])
    m.fa.set_flow_style()
    return m


def _same_pose(entry, T: np.ndarray) -> bool:
    try:
        return np.allclose(transform_from_xyz_rpy(entry["xyz"], entry["rpy"]), T, atol=1e-6)
    except (KeyError, TypeError, ValueError):
        return False


def _component_entry(item, source: tuple[Path, str], folder: Path) -> CommentedMap:
    mesh_file, units = source
    entry = CommentedMap(
        [
            ("name", item.name),
            ("kind", item.kind),
            ("mesh", os.path.relpath(mesh_file, folder)),
            ("mesh_units", units),
            ("color", _flow(item.color)),
            ("placement", _placement(item.item2world)),
        ]
    )
    if item.features:
        entry["features"] = CommentedMap((k, _feature_entry(item, k)) for k in item.features)
    if item.form_tolerance_mm > 0:
        entry["form_tolerance_mm"] = float(item.form_tolerance_mm)
    return entry


def _feature_entry(item, name: str):
    """``[x, y, z]`` for a corner, ``{at, kind, ...}`` (one line) for another kind."""
    kind = item.feature_kinds.get(name)
    if kind is None or kind.kind == "corner":
        return _flow(item.features[name])
    entry = CommentedMap(kind.to_yaml(np.round(item.features[name], _DECIMALS)))
    entry["at"] = _flow(entry["at"])
    if "normal" in entry:
        entry["normal"] = _flow(np.round(entry["normal"], _DECIMALS))
    entry.fa.set_flow_style()
    return entry


def _stored_point(value) -> np.ndarray | None:
    value = value.get("at") if isinstance(value, dict) else value
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None


def _update_component(entry: CommentedMap, item) -> None:
    if not _same_pose(entry.get("placement", {}), item.item2world):
        entry["placement"] = _placement(item.item2world)
    features = entry.get("features")
    if features is None and item.features:
        features = entry["features"] = CommentedMap()
    for name, point in item.features.items():
        stored = _stored_point(features[name]) if name in features else None
        stored_kind = (
            features[name].get("kind", "corner") if name in features and isinstance(features[name], dict) else "corner"
        )
        kind = item.feature_kinds.get(name)
        if (
            stored is None
            or stored.shape != (3,)
            or not np.allclose(stored, point, atol=1e-6)
            or stored_kind != (kind.kind if kind else "corner")
        ):
            features[name] = _feature_entry(item, name)
    for name in [k for k in (features or {}) if k not in item.features]:
        del features[name]


def _task_entry(task) -> CommentedMap:
    entry = CommentedMap([("name", task.name)])
    if task.component:
        entry["component"] = task.component
    entry["tcp2base"] = _placement(task.tcp2base)
    entry["approach_mm"] = float(round(task.approach_mm, _DECIMALS))
    if task.tolerance_mm != DEFAULT_TOLERANCE_MM:
        entry["tolerance_mm"] = float(task.tolerance_mm)
    return entry


def save_workcell(workcell: Workcell, path: str | Path | None = None) -> Path:
    """Write ``workcell``'s components and task locations into its YAML (or a copy at ``path``,
    whose relative paths are then rewritten for its folder). Returns the file written."""
    source = Path(workcell.path)
    target = Path(path) if path is not None else source
    yaml = YAML()
    yaml.preserve_quotes = True
    yaml.width = 4096
    yaml.indent(mapping=2, sequence=4, offset=2)  # the style of the bundled and new-cell files
    try:
        doc = yaml.load(source.read_text(encoding="utf-8"))
    except Exception as exc:  # ruamel's errors: the file changed under us since it was loaded
        raise FileFormatError(source, f"cannot re-read the workcell to save it: {exc}") from None
    if target.resolve().parent != source.resolve().parent:
        _rebase_paths(doc, source.resolve().parent, target.resolve().parent)
    folder = target.resolve().parent
    files = workcell.meta.get("mesh_files", {})
    entries = {e["name"]: e for e in doc["components"]}
    for item in workcell.components:
        if item.name in entries:
            _update_component(entries[item.name], item)
        elif item.name in files:
            doc["components"].append(_component_entry(item, files[item.name], folder))
    keep = {c.name for c in workcell.components}
    for i in reversed(range(len(doc["components"]))):
        if doc["components"][i]["name"] not in keep:
            del doc["components"][i]
    tasks = doc.get("task_locations")
    if tasks is None:
        tasks = doc["task_locations"] = CommentedSeq()
    by_name = {t["name"]: t for t in tasks}
    for task in workcell.task_locations.values():
        entry = by_name.get(task.name)
        if entry is None:
            tasks.append(_task_entry(task))
            continue
        if not _same_pose(entry.get("tcp2base", {}), task.tcp2base):
            entry["tcp2base"] = _placement(task.tcp2base)
        if abs(float(entry.get("approach_mm", 0.0)) - task.approach_mm) > 1e-9:
            entry["approach_mm"] = float(round(task.approach_mm, _DECIMALS))
        if abs(float(entry.get("tolerance_mm", DEFAULT_TOLERANCE_MM)) - task.tolerance_mm) > 1e-12:
            entry["tolerance_mm"] = float(task.tolerance_mm)
    for i in reversed(range(len(tasks))):
        if tasks[i]["name"] not in workcell.task_locations:
            del tasks[i]
    out = io.StringIO()
    yaml.dump(doc, out)
    atomic_write_text(target, out.getvalue())
    return target


def _rebase_paths(doc, old: Path, new: Path) -> None:
    def moved(value: str) -> str:
        return value if os.path.isabs(value) else os.path.relpath(old / value, new)

    robot = doc["robot"]
    robot["urdf"] = moved(robot["urdf"])
    if robot.get("package_paths"):
        for i, p in enumerate(robot["package_paths"]):
            robot["package_paths"][i] = moved(p)
    if doc.get("camera") and doc["camera"].get("intrinsics"):
        doc["camera"]["intrinsics"] = moved(doc["camera"]["intrinsics"])
    for c in doc["components"]:
        c["mesh"] = moved(c["mesh"])
