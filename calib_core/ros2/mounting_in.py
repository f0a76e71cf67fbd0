"""A camera mounting from the launch file another tool wrote for ``tf2_ros``'s ``static_transform_publisher``.

MoveIt 2's hand-eye calibration saves its result as a ROS 2 Python launch file with one
``static_transform_publisher`` node (``--frame-id``, ``--child-frame-id``, ``--x --y --z`` in metres, then
``--qx --qy --qz --qw`` or ``--roll --pitch --yaw`` in radians); MoveIt Calibration on ROS 1 and many hand-written
setups use an XML launch file whose ``args`` are positional (``x y z yaw pitch roll frame child`` or ``x y z qx qy
qz qw frame child``); videocal writes the first form itself (:mod:`calib_core.ros2.mounting_out`).

The Python file is read as a syntax tree and never run: only string and number constants in the node's
``arguments`` are taken (a launch file is a program; a calibration result must not be able to do anything).
The transform is the child frame in the parent frame (``child2parent``), as the publisher puts it on ``/tf_static``.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.documents import read_text
from calib_core.errors import FileFormatError
from calib_core.frames import make_transform

LAUNCH_SUFFIXES = (".launch.py", ".launch", ".launch.xml")
_PUBLISHER = "static_transform_publisher"
_NAMED = {
    "--x",
    "--y",
    "--z",
    "--qx",
    "--qy",
    "--qz",
    "--qw",
    "--roll",
    "--pitch",
    "--yaw",
    "--frame-id",
    "--child-frame-id",
}


@dataclass(frozen=True)
class StaticTransform:
    """``child`` in ``parent``: ``child2parent_mm`` (4, 4), mm."""

    parent: str
    child: str
    child2parent_mm: np.ndarray


def is_launch_file(path: str | Path) -> bool:
    name = Path(path).name.lower()
    return any(name.endswith(suffix) for suffix in LAUNCH_SUFFIXES)


def read_static_transform(path: str | Path) -> StaticTransform:
    """The one ``static_transform_publisher`` of a ROS 2 Python or an XML launch file. :class:`FileFormatError` names
    the
    file for no such node, several, or arguments that are not a transform."""
    path = Path(path)
    text = read_text(path, "launch file", max_bytes=1024 * 1024)
    found = _python_nodes(path, text) if path.name.lower().endswith(".py") else _xml_nodes(path, text)
    if not found:
        raise FileFormatError(path, f"no {_PUBLISHER} node with constant arguments in this launch file")
    if len(found) > 1:
        frames = "; ".join(" -> ".join(_frames(path, args)) for args in found)
        raise FileFormatError(path, f"{len(found)} {_PUBLISHER} nodes ({frames}): give a file with the camera's alone")
    return _transform(path, found[0])


def _python_nodes(path: Path, text: str) -> list[list[str]]:
    try:
        tree = ast.parse(text, filename=str(path))
    except (SyntaxError, ValueError) as exc:
        raise FileFormatError(path, f"not a Python launch file: {exc}") from None
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        keywords = {k.arg: k.value for k in node.keywords if k.arg}
        executable = keywords.get("executable", keywords.get("node_executable"))
        if not (isinstance(executable, ast.Constant) and executable.value == _PUBLISHER):
            continue
        arguments = keywords.get("arguments")
        if not isinstance(arguments, (ast.List, ast.Tuple)) or not all(
            isinstance(a, ast.Constant) and isinstance(a.value, (str, int, float)) for a in arguments.elts
        ):
            raise FileFormatError(
                path,
                f"the {_PUBLISHER} node's arguments must be a list of constants (the file is read, never run)",
                "arguments",
            )
        out.append([str(a.value) for a in arguments.elts])
    return out


def _xml_nodes(path: Path, text: str) -> list[list[str]]:
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise FileFormatError(path, f"not an XML launch file: {exc}") from None
    out = []
    for node in root.iter("node"):
        if node.get("type", node.get("exec")) == _PUBLISHER:
            out.append(node.get("args", "").split())
    return out


def _frames(path: Path, args: list[str]) -> tuple[str, str]:
    if any(a in _NAMED for a in args):
        named = _named(path, args)
        return named.get("--frame-id", "?"), named.get("--child-frame-id", "?")
    if args and _is_number(args[-1]):
        args = args[:-1]  # ROS 1 tf's period
    return (args[-2], args[-1]) if len(args) >= 8 else ("?", "?")


def _named(path: Path, args: list[str]) -> dict[str, str]:
    if len(args) % 2:
        raise FileFormatError(
            path, f"{_PUBLISHER}'s named arguments come in pairs (--x 0.1 ...), got {len(args)} words", "arguments"
        )
    named = dict(zip(args[::2], args[1::2]))
    unknown = set(named) - _NAMED
    if unknown:
        raise FileFormatError(path, f"unknown {_PUBLISHER} argument(s) {', '.join(sorted(unknown))}", "arguments")
    return named


def _number(path: Path, text: str, name: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise FileFormatError(path, f"{name} must be a number, got {text!r}", "arguments") from None
    if not np.isfinite(value) or abs(value) > 1e4:
        raise FileFormatError(path, f"{name} = {text} is not a mounting's size (metres, radians)", "arguments")
    return value


def _transform(path: Path, args: list[str]) -> StaticTransform:
    if any(a in _NAMED for a in args):
        named = _named(path, args)
        for key in ("--frame-id", "--child-frame-id"):
            if key not in named:
                raise FileFormatError(path, f"{_PUBLISHER} has no {key}", "arguments")
        xyz = [_number(path, named.get(f"--{k}", "0"), k) for k in "xyz"]
        quaternion = [k for k in ("--qx", "--qy", "--qz", "--qw") if k in named]
        euler = [k for k in ("--roll", "--pitch", "--yaw") if k in named]
        if quaternion and euler:
            raise FileFormatError(path, "both a quaternion and roll/pitch/yaw: give one", "arguments")
        if quaternion:
            q = np.array(
                [
                    _number(path, named.get(k, "1" if k == "--qw" else "0"), k[2:])
                    for k in ("--qx", "--qy", "--qz", "--qw")
                ]
            )
            R = _quaternion(path, q)
        else:  # tf2's setRPY: fixed axes x, y, z (R = Rz(yaw) Ry(pitch) Rx(roll))
            R = Rotation.from_euler(
                "xyz", [_number(path, named.get(f"--{k}", "0"), k) for k in ("roll", "pitch", "yaw")]
            ).as_matrix()
        parent, child = named["--frame-id"], named["--child-frame-id"]
    elif len(args) == 10 or (
        len(args) == 9 and not _is_number(args[8])
    ):  # x y z qx qy qz qw frame child [period: ROS 1's tf]
        xyz = [_number(path, a, n) for a, n in zip(args[:3], "xyz")]
        R = _quaternion(path, np.array([_number(path, a, n) for a, n in zip(args[3:7], ("qx", "qy", "qz", "qw"))]))
        parent, child = args[7], args[8]
    elif len(args) in (8, 9):  # x y z yaw pitch roll frame child [period]
        xyz = [_number(path, a, n) for a, n in zip(args[:3], "xyz")]
        yaw, pitch, roll = (_number(path, a, n) for a, n in zip(args[3:6], ("yaw", "pitch", "roll")))
        R = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()
        parent, child = args[6], args[7]
    else:
        raise FileFormatError(
            path,
            f"{_PUBLISHER}'s arguments are not a transform: expected x y z yaw pitch roll frame child, "
            f"x y z qx qy qz qw frame child, or the named form (--x ... --frame-id ...), got {' '.join(args)!r}",
            "arguments",
        )
    return StaticTransform(parent.lstrip("/"), child.lstrip("/"), make_transform(R, np.array(xyz) * 1000.0))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _quaternion(path: Path, q: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(q))
    if abs(norm - 1.0) > 1e-3:
        raise FileFormatError(path, f"not a unit quaternion (norm {norm:.4f})", "arguments")
    return Rotation.from_quat(q / norm).as_matrix()
