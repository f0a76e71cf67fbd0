"""Reading a workcell YAML file (``safe_load``: data only) with strict validation.

Every error is a :class:`~calib_core.errors.FileFormatError` naming the file and the field
(``components[2].placement.rpy``): unknown keys, missing meshes, wrong units, duplicate
names, malformed numbers. The schema is in ``docs/workcell.md``.
"""

from __future__ import annotations

import math

from pathlib import Path

import numpy as np
from calib_core.documents import read_yaml

from calib_core.names import name_problem
from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy
from calib_core.mesh_files import MESH_SCALE, load_mesh
from calib_core.robot.errors import RobotSpecError
from calib_core.robot.model import load_robot
from calib_core.scene import SceneItem
from calib_core.workcell.feature_kinds import CORNER, KINDS, FeatureKind
from calib_core.workcell.model import TaskLocation, Workcell
from calib_core.workcell.robot_section import check_against_robot, read_robot_section
from calib_core.workcell.site_section import read_site_section
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM, SAFETY_KEYS, SafetyLimits

from calib_core.bundled import DEFAULT_WORKCELL  # noqa: E402 (re-exported: the package's name for it)

SCHEMA_VERSION = 2
# Version 1 files (the bundled robot frame names, six axes) read as they are: every key of 2 is optional.
_READABLE_VERSIONS = (1, 2)
_TOP_KEYS = {
    "schema_version",
    "name",
    "units",
    "robot",
    "camera",
    "components",
    "task_locations",
    "hand_eye_board",
    "safety",
    "site",
}
_COMPONENT_KEYS = {"name", "kind", "mesh", "mesh_units", "color", "placement", "features", "form_tolerance_mm"}
FORM_TOLERANCE_LIMIT_MM = 20.0
"""A part further from its CAD than this is not the part the CAD describes: model it anew."""
_TASK_KEYS = {"name", "component", "tcp2base", "approach_mm", "tolerance_mm"}
_KINDS = {"component", "fixture"}


class _Reader:
    """Validation helpers that know the file, so every error names it."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, field: str | None, message: str) -> FileFormatError:
        return FileFormatError(self.path, message, field)

    def mapping(self, value, field: str, allowed: set[str], required: set[str]) -> dict:
        if not isinstance(value, dict):
            raise self.fail(field, f"must be a mapping, got {type(value).__name__}")
        unknown = set(value) - allowed
        if unknown:
            raise self.fail(
                field, f"unknown key(s) {', '.join(sorted(map(str, unknown)))}; allowed: {', '.join(sorted(allowed))}"
            )
        missing = required - set(value)
        if missing:
            raise self.fail(field, f"missing key(s) {', '.join(sorted(missing))}")
        return value

    def number(self, value, field: str) -> float:
        try:
            v = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan
        except OverflowError:  # an integer past any float
            v = math.nan
        if not math.isfinite(v):
            raise self.fail(field, f"must be a finite number, got {value!r}")
        return v

    def vector(self, value, n: int, field: str) -> np.ndarray:
        if not isinstance(value, (list, tuple)) or len(value) != n:
            raise self.fail(field, f"must be a list of {n} numbers, got {value!r}")
        return np.array([self.number(v, f"{field}[{i}]") for i, v in enumerate(value)])

    def choice(self, value, field: str, options) -> str:
        if not isinstance(value, str) or value not in options:
            raise self.fail(field, f"must be one of {', '.join(sorted(options))}, got {value!r}")
        return value

    def text(self, value, field: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(field, f"must be a non-empty string, got {value!r}")
        return value

    def name(self, value, field: str) -> str:
        """A name (of a component, a feature, a task location): text without control characters."""
        why = name_problem(value)
        if why is not None:
            raise self.fail(field, f"the name {str(value)[:60]!r} {why}")
        return value

    def placement(self, value, field: str) -> np.ndarray:
        """A placement ``{xyz: mm, rpy: deg}``: within 10 km and a few turns (1e308 mm, 1e23 deg: a damaged file,
        whose renders and moves would be nothing)."""
        from calib_core.mesh_files import MAX_COORDINATE_MM

        value = self.mapping(value, field, {"xyz", "rpy"}, {"xyz", "rpy"})
        xyz, rpy = self.vector(value["xyz"], 3, f"{field}.xyz"), self.vector(value["rpy"], 3, f"{field}.rpy")
        if np.abs(xyz).max() > MAX_COORDINATE_MM:
            raise self.fail(
                f"{field}.xyz",
                f"lies {np.abs(xyz).max():.3g} mm away, beyond {MAX_COORDINATE_MM:g} mm: placements are in mm",
            )
        if np.abs(rpy).max() > MAX_PLACEMENT_DEG:
            raise self.fail(
                f"{field}.rpy",
                f"turns {np.abs(rpy).max():.3g} deg, beyond {MAX_PLACEMENT_DEG:g} deg: angles are in deg",
            )
        return transform_from_xyz_rpy(xyz, rpy)

    def file(self, value, field: str) -> Path:
        text = self.text(value, field)
        try:
            path = (self.path.parent / text).resolve()
            found = path.is_file()
        except (ValueError, OSError) as exc:  # a NUL byte, a name longer than the file system takes
            raise self.fail(
                field,
                f"not a usable file name ({exc.strerror if isinstance(exc, OSError) and exc.strerror else exc}): "
                f"{text[:80]!r}",
            ) from None
        if not found:
            raise self.fail(field, f"file not found: {path}")
        return path


def _component(reader: _Reader, raw, i: int) -> SceneItem:
    f = f"components[{i}]"
    raw = reader.mapping(raw, f, _COMPONENT_KEYS, {"name", "mesh", "mesh_units", "placement"})
    name = reader.name(raw["name"], f"{f}.name")
    kind = reader.choice(raw.get("kind", "component"), f"{f}.kind", _KINDS)
    units = reader.choice(raw["mesh_units"], f"{f}.mesh_units", set(MESH_SCALE))
    mesh_path = reader.file(raw["mesh"], f"{f}.mesh")
    try:
        mesh = load_mesh(mesh_path, units)
    except FileFormatError as exc:  # said as the workcell's field, the mesh file named
        raise reader.fail(f"{f}.mesh", f"mesh {mesh_path.name}: {exc.detail}") from None
    color = tuple(reader.vector(raw.get("color", [0.7, 0.7, 0.7]), 3, f"{f}.color"))
    if not all(0.0 <= c <= 1.0 for c in color):
        raise reader.fail(f"{f}.color", f"RGB values must lie in [0, 1], got {list(color)}")
    features_raw = raw.get("features", {}) or {}
    if not isinstance(features_raw, dict):
        raise reader.fail(
            f"{f}.features", "must be a mapping of name: [x, y, z] (mm), or name: {at: [x, y, z], kind: ...}"
        )
    features, kinds = {}, {}
    for k, v in features_raw.items():
        reader.name(k, f"{f}.features.{str(k)[:40]!r}")
        features[str(k)], feature_kind = _feature(reader, v, f"{f}.features.{k}")
        if feature_kind.kind != "corner":
            kinds[str(k)] = feature_kind
    form = reader.number(raw.get("form_tolerance_mm", 0.0), f"{f}.form_tolerance_mm")
    if not 0.0 <= form <= FORM_TOLERANCE_LIMIT_MM:
        raise reader.fail(
            f"{f}.form_tolerance_mm",
            f"must lie in [0, {FORM_TOLERANCE_LIMIT_MM:g}] mm (1-sigma of the part's features about their CAD "
            f"positions), got {form:g}",
        )
    return SceneItem(
        name=name,
        mesh=mesh,
        item2world=reader.placement(raw["placement"], f"{f}.placement"),
        color=color,
        kind=kind,
        features=features,
        feature_kinds=kinds,
        form_tolerance_mm=form,
    )


MAX_PLACEMENT_DEG = 3600.0
"""The largest roll, pitch or yaw (deg, ten turns) a placement may hold; a bigger one is a damaged number."""

_FEATURE_KEYS = {"at", "kind", "radius_mm", "normal"}


def _feature_point(reader, value, field: str) -> np.ndarray:
    from calib_core.mesh_files import MAX_COORDINATE_MM

    point = reader.vector(value, 3, field)
    if np.abs(point).max() > MAX_COORDINATE_MM:
        raise reader.fail(
            field,
            f"lies {np.abs(point).max():.3g} mm from its component's origin, beyond {MAX_COORDINATE_MM:g} mm: "
            "features are in mm in the component's frame",
        )
    return point


def _feature(reader, value, field: str) -> tuple[np.ndarray, FeatureKind]:
    """A feature's point (3,) mm and its kind: ``[x, y, z]`` (a corner) or ``{at, kind, radius_mm, normal}``."""
    if not isinstance(value, dict):
        return _feature_point(reader, value, field), CORNER
    entry = reader.mapping(value, field, _FEATURE_KEYS, {"at"})
    point = _feature_point(reader, entry["at"], f"{field}.at")
    kind = reader.choice(entry.get("kind", "corner"), f"{field}.kind", set(KINDS))
    if kind != "circle":
        for key in ("radius_mm", "normal"):
            if key in entry:
                raise reader.fail(f"{field}.{key}", f"applies to a circle only (this feature is a {kind})")
        return point, FeatureKind(kind)
    for key in ("radius_mm", "normal"):
        if key not in entry:
            raise reader.fail(
                f"{field}.{key}", "a circle needs radius_mm (mm) and normal ([x, y, z] in the component's frame)"
            )
    radius = reader.number(entry["radius_mm"], f"{field}.radius_mm")
    normal = reader.vector(entry["normal"], 3, f"{field}.normal")
    try:
        return point, FeatureKind("circle", radius, tuple(normal))
    except ValueError as exc:
        raise reader.fail(field, str(exc)) from None


def _task(reader: _Reader, raw, i: int, components: set[str]) -> TaskLocation:
    f = f"task_locations[{i}]"
    raw = reader.mapping(raw, f, _TASK_KEYS, {"name", "tcp2base"})
    component = raw.get("component")
    if component is not None and not isinstance(component, str):
        raise reader.fail(f"{f}.component", f"must be the name of one component, got {component!r}")
    if component is not None and component not in components:
        raise reader.fail(f"{f}.component", f"no component called {component!r}")
    approach = reader.number(raw.get("approach_mm", 0.0), f"{f}.approach_mm")
    if approach < 0:
        raise reader.fail(f"{f}.approach_mm", f"must be >= 0, got {approach}")
    tolerance = reader.number(raw.get("tolerance_mm", DEFAULT_TOLERANCE_MM), f"{f}.tolerance_mm")
    if tolerance <= 0:
        raise reader.fail(f"{f}.tolerance_mm", f"must be > 0 mm, got {tolerance}")
    return TaskLocation(
        reader.name(raw["name"], f"{f}.name"),
        reader.placement(raw["tcp2base"], f"{f}.tcp2base"),
        approach,
        component,
        tolerance,
    )


def _safety(reader: _Reader, raw) -> SafetyLimits:
    if raw is None:
        return SafetyLimits()
    raw = reader.mapping(raw, "safety", SAFETY_KEYS, set())
    values = {}
    for key, value in raw.items():
        number = reader.number(value, f"safety.{key}")
        if number <= 0:
            raise reader.fail(f"safety.{key}", f"must be > 0, got {number}")
        values[key] = number
    return SafetyLimits(**values)


def load_site_section(path: str | Path):
    """Only the ``site:`` section of a workcell file (``None`` when it has none), without loading its
    robot: the command line decides from it whether a cell is real or simulated before anything starts."""
    path = Path(path)
    reader = _Reader(path)
    data = reader.mapping(read_yaml(path, "workcell file"), "(top level)", _TOP_KEYS, set())
    return read_site_section(reader, data["site"], path.parent) if data.get("site") is not None else None


def load_workcell(path: str | Path = DEFAULT_WORKCELL) -> Workcell:
    """Read and validate a workcell file; raise :class:`FileFormatError` naming the field at fault."""
    path = Path(path)
    reader = _Reader(path)
    data = read_yaml(path, "workcell file")  # size, nesting and aliases bounded before anything is built
    data = reader.mapping(data, "(top level)", _TOP_KEYS, {"schema_version", "units", "robot", "components"})
    if (
        isinstance(data["schema_version"], bool)
        or not isinstance(data["schema_version"], int)
        or data["schema_version"] not in _READABLE_VERSIONS
    ):
        raise reader.fail(
            "schema_version",
            f"this videocal reads versions {', '.join(map(str, _READABLE_VERSIONS))}, the file is version "
            f"{data['schema_version']!r}",
        )
    units = reader.mapping(data["units"], "units", {"length", "angle"}, {"length", "angle"})
    if units["length"] != "mm" or units["angle"] != "deg":
        raise reader.fail("units", f"placements must be in mm and deg, got {units['length']!r} and {units['angle']!r}")
    robot_spec = read_robot_section(reader, data["robot"])
    try:
        robot = load_robot(robot_spec)
    except RobotSpecError as exc:  # the workcell names something its URDF lacks: name the workcell's field
        raise reader.fail(exc.field, f"{exc.detail} (in {robot_spec.urdf.name})") from None
    home = check_against_robot(reader, robot_spec, robot)
    intrinsics_path = None
    if data.get("camera") is not None:
        camera = reader.mapping(data["camera"], "camera", {"intrinsics"}, {"intrinsics"})
        intrinsics_path = reader.file(camera["intrinsics"], "camera.intrinsics")
    if not isinstance(data["components"], list) or not data["components"]:
        raise reader.fail("components", "must be a non-empty list")
    components: list[SceneItem] = []
    for i, raw in enumerate(data["components"]):
        item = _component(reader, raw, i)
        if any(c.name == item.name for c in components):
            raise reader.fail(f"components[{i}].name", f"duplicate component name {item.name!r}")
        components.append(item)
    names = {c.name for c in components}
    tasks: dict[str, TaskLocation] = {}
    raw_tasks = data.get("task_locations", []) or []
    if not isinstance(raw_tasks, list):
        raise reader.fail("task_locations", "must be a list")
    for i, raw in enumerate(raw_tasks):
        task = _task(reader, raw, i, names)
        if task.name in tasks:
            raise reader.fail(f"task_locations[{i}].name", f"duplicate task location name {task.name!r}")
        tasks[task.name] = task
    meta = {}
    if data.get("hand_eye_board") is not None:
        # Where the hand-eye board's centre stands (x along its columns, y down its rows, z into it).
        meta["hand_eye_board_centre"] = reader.placement(data["hand_eye_board"], "hand_eye_board")
    safety = _safety(reader, data.get("safety"))
    if data.get("site") is not None:
        meta["site"] = read_site_section(reader, data["site"], path.parent)
    return Workcell(
        str(data.get("name", path.stem)), path, components, tasks, robot_spec, intrinsics_path, home, meta, safety
    )
