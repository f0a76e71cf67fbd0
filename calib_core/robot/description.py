"""From a robot description file on disk to URDF text Pinocchio can read.

Vendors ship xacro files and URDFs whose meshes are named ``package://pkg/path`` or by a path
relative to the URDF. Here a xacro file is expanded with the ``xacro`` package, and every mesh
reference is resolved to an absolute path through the cell's package paths (then
``ROS_PACKAGE_PATH``), so what Pinocchio gets needs no ROS. A mesh that cannot be found is an
error naming the URDF, the link and every place looked in.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

from calib_core.errors import FileFormatError
from calib_core.mesh_files import MESH_SUFFIXES
from calib_core.robot.ros_packages import find_package, search_roots
from calib_core.robot.xacro_expand import expand_xacro


def _is_xacro(path: Path, text: str) -> bool:
    return (
        path.suffix == ".xacro" or path.name.endswith(".urdf.xacro") or "http://www.ros.org/wiki/xacro" in text[:4000]
    )


def package_search_roots(package_paths: Iterable[str | Path]) -> list[Path]:
    """The folders searched for packages (:func:`calib_core.robot.ros_packages.search_roots`)."""
    return search_roots(package_paths)


def _package_candidates(package: str, rest: str, roots: list[Path]) -> list[Path]:
    # A root is either a folder that holds packages (root/pkg/rest) or a package itself (root/rest); else the
    # package is looked for by its package.xml, as $(find) does.
    candidates = []
    for root in roots:
        candidates.append(root / package / rest)
        if root.name == package:
            candidates.append(root / rest)
    if not any(c.is_file() for c in candidates):
        found = find_package(package, roots)
        if found is not None:
            candidates.append(found / rest)
    return candidates


def resolve_uri(uri: str, urdf_dir: Path, roots: list[Path]) -> tuple[Path | None, list[Path]]:
    """The file a mesh reference names, and every place looked in (for the error message)."""
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://") :].partition("/")
        looked = _package_candidates(package, rest, roots)
    elif uri.startswith("file://"):
        looked = [Path(uri[len("file://") :])]
    else:
        looked = [Path(uri) if Path(uri).is_absolute() else urdf_dir / uri]
    for candidate in looked:
        if candidate.is_file():
            return candidate.resolve(), looked
    return None, looked


def _resolve_meshes(root: ET.Element, path: Path, roots: list[Path], uris: dict[str, str] | None = None) -> None:
    for link in root.iter("link"):
        for role in ("visual", "collision"):
            for element in link.iter(role):
                for mesh in element.iter("mesh"):
                    uri = mesh.get("filename", "")
                    found, looked = resolve_uri(uri, path.parent, roots)
                    where = f"link '{link.get('name')}' {role} mesh"
                    if found is None:
                        places = (
                            "; ".join(str(p) for p in looked)
                            or "(no package path: add robot.package_paths to the workcell)"
                        )
                        raise FileFormatError(path, f"{where} {uri!r} not found; looked in: {places}")
                    if found.suffix.lower() not in MESH_SUFFIXES:
                        raise FileFormatError(
                            path,
                            f"{where} {uri!r}: unsupported format {found.suffix!r}; use STL, OBJ, DAE, glTF/GLB or PLY",
                        )
                    mesh.set("filename", str(found))
                    if uris is not None:
                        uris[str(found)] = uri


def read_description(
    path: str | Path,
    package_paths: Iterable[str | Path] = (),
    xacro_args: dict[str, str] | None = None,
    mesh_uris: dict[str, str] | None = None,
) -> str:
    """URDF text of a URDF or xacro file with every mesh as an absolute path. A xacro file is expanded with
    ``xacro_args`` (``$(arg name)``) and packages found as :mod:`calib_core.robot.ros_packages` says.
    ``mesh_uris``, when given, receives each absolute path's reference as the file wrote it (``package://...``),
    so a description written back for ROS keeps them.

    :class:`FileFormatError` names the file for a missing, unreadable or malformed file, a xacro
    that cannot be expanded, and (with the link) a mesh that cannot be found.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileFormatError(path, "no such robot description file") from None
    except (IsADirectoryError, UnicodeDecodeError, PermissionError) as exc:
        raise FileFormatError(path, f"cannot read: {exc}") from None
    if _is_xacro(path, text):
        text = expand_xacro(path, package_search_roots(package_paths), xacro_args)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise FileFormatError(path, f"not valid XML: {exc}") from None
    if root.tag != "robot":
        raise FileFormatError(path, f"not a URDF: the top element is <{root.tag}>, not <robot>")
    _check_numbers(root, path)
    _resolve_meshes(root, path, package_search_roots(package_paths), mesh_uris)
    return ET.tostring(root, encoding="unicode")


def _numbers(text: str | None, n: int) -> list[float] | None:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return None
    return values if len(values) == n else None


MAX_URDF_JOINTS = 500
"""The most joints a description may have (a humanoid has about 50; a 2999-joint URDF exhausted memory)."""
MAX_ORIGIN_M = 1000.0
"""The farthest an origin may place a link from its parent (m): beyond, a unit error (mm read as m)."""
MAX_ANGLE_RAD = 100.0
"""The largest angle (rad, 16 turns) an origin's rpy or a revolute joint's limit may hold: a multi-turn joint has a
few turns; beyond, degrees written as radians, or a number that is no angle (1e23 rad: no digit of its turn left)."""


def _check_numbers(root: ET.Element, path: Path) -> None:
    """Origins finite and within reach (a NaN origin made Pinocchio drop the visual without a word), joint axes
    not zero, joint limits in order, and no more joints than a robot has: the robot model every move is
    previewed with must be the one the file says."""
    joints = root.findall(".//joint")
    if len(joints) > MAX_URDF_JOINTS:
        raise FileFormatError(
            path, f"{len(joints)} joints: over the limit of {MAX_URDF_JOINTS} for one robot description"
        )
    for parent in root.iter():
        for origin in parent.findall("origin"):
            for attr in ("xyz", "rpy"):
                if origin.get(attr) is None:
                    continue
                values = _numbers(origin.get(attr), 3)
                owner = f"{parent.tag} '{parent.get('name')}'" if parent.get("name") else f"a {parent.tag}"
                if values is None or not all(math.isfinite(v) for v in values):
                    raise FileFormatError(
                        path, f"{owner}: origin {attr}={origin.get(attr)!r} must be three finite numbers"
                    )
                if attr == "rpy" and max(abs(v) for v in values) > MAX_ANGLE_RAD:
                    raise FileFormatError(
                        path,
                        f"{owner}: origin rpy={origin.get(attr)!r} turns more than {MAX_ANGLE_RAD:g} rad: a URDF's "
                        "angles are radians within a turn or so (degrees written as radians?)",
                    )
                if attr == "xyz" and max(abs(v) for v in values) > MAX_ORIGIN_M:
                    raise FileFormatError(
                        path,
                        f"{owner}: origin xyz={origin.get(attr)!r} is over {MAX_ORIGIN_M:g} m away: a URDF is in "
                        "metres (mm written as m?)",
                    )
    for joint in root.iter("joint"):
        axis = joint.find("axis")
        if axis is not None and joint.get("type") in ("revolute", "continuous", "prismatic"):
            values = _numbers(axis.get("xyz", "1 0 0"), 3)
            if values is None or not all(math.isfinite(v) for v in values) or math.hypot(*values) < 1e-9:
                raise FileFormatError(
                    path,
                    f"joint '{joint.get('name')}': axis xyz={axis.get('xyz')!r} must be three finite numbers, not all "
                    "zero",
                )
        limit = joint.find("limit")
        if limit is None or joint.get("type") not in ("revolute", "prismatic"):
            continue
        lo, hi = (_numbers(limit.get(k, "0"), 1) for k in ("lower", "upper"))
        if lo is None or hi is None or not all(math.isfinite(v) for v in lo + hi):
            raise FileFormatError(
                path,
                f"joint '{joint.get('name')}': limit lower={limit.get('lower')!r} upper={limit.get('upper')!r} must be "
                "finite numbers",
            )
        reach = MAX_ORIGIN_M if joint.get("type") == "prismatic" else MAX_ANGLE_RAD
        if max(abs(lo[0]), abs(hi[0])) > reach:
            raise FileFormatError(
                path,
                f"joint '{joint.get('name')}': limit lower={limit.get('lower')!r} upper={limit.get('upper')!r} is "
                f"beyond {reach:g} {'m' if reach == MAX_ORIGIN_M else 'rad'}: no joint moves that far (a joint without "
                "limits is type continuous)",
            )
        for key in ("velocity", "effort"):
            value = _numbers(limit.get(key), 1) if limit.get(key) is not None else [0.0]
            if value is None or not math.isfinite(value[0]) or value[0] < 0:
                raise FileFormatError(
                    path,
                    f"joint '{joint.get('name')}': limit {key}={limit.get(key)!r} must be a finite number, 0 or more",
                )
        if lo[0] > hi[0]:
            raise FileFormatError(
                path, f"joint '{joint.get('name')}': limit lower ({lo[0]:g}) is above upper ({hi[0]:g})"
            )
