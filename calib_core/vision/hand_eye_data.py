"""Hand-eye (and robot calibration) data from files: images, each with the robot's pose or joints.

Two layouts are read:

- **ROS-Industrial's** ``cal_data.yaml`` (its ``industrial_calibration`` data sets): ``data:`` a list
  of ``{image: PATH, pose: PATH}``, relative to the file; each pose file holds ``x y z`` (m) and
  ``qx qy qz qw``, the robot's tool in its base. Optional: ``target_finder`` (the board),
  ``intrinsics`` (``fx fy cx cy``, no distortion, no image size), ``static_camera``.
- **A CSV** with a header: ``image`` and either ``x_mm,y_mm,z_mm,qx,qy,qz,qw`` (the flange in the
  base) or one column per joint, named as the robot's joints or ``j1..jn`` (deg, mm for a prismatic
  joint), each row one view. With joints, an optional ``component`` column after ``image`` names the
  workcell's surveyed component a view shows instead of the board (empty: a board view), for the
  robot calibration's tie to the cell.
- **A JSON pose file**: a list of ``{image, flange2base}``, the tool's pose in the base as a row-major 4 x 4 with its
  translation in metres (as controllers and ROS report it; the form of the workplace's shared hand-eye sets), or
  ``{"length_unit": "mm" | "m", "poses": [...]}`` to say the unit.

Every problem is a :class:`~calib_core.errors.FileFormatError` naming the file, the row or entry
and the field; nothing is read from an image until it is used.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.documents import csv_numbers, finite_number, read_grey_image, read_text, read_yaml
from calib_core.errors import FileFormatError
from calib_core.frames import make_transform

POSE_COLUMNS = ("x_mm", "y_mm", "z_mm", "qx", "qy", "qz", "qw")
MAX_VIEWS = 2000
_ROS_DICTIONARIES = {
    getattr(cv2.aruco, n): n for n in dir(cv2.aruco) if n.startswith("DICT_") and isinstance(getattr(cv2.aruco, n), int)
}


@dataclass(frozen=True)
class PosedImage:
    """One view: ``image_path``; ``flange2base`` (4, 4) mm or ``joints_deg`` (n,), one of them."""

    name: str
    image_path: Path
    flange2base: np.ndarray | None = None
    joints_deg: np.ndarray | None = None
    component: str | None = None
    """The surveyed component the view shows instead of the board (a CSV's ``component`` column)."""


@dataclass(frozen=True)
class PosedImages:
    """The views of a data set; what the file says about the board (``board_text``, a ``--board``
    text), the camera (``pinhole``: fu, fv, cx, cy px, no size) and ``static_camera`` (``None``: it
    does not say)."""

    source: Path
    views: list[PosedImage]
    board_text: str | None = None
    pinhole: tuple[float, float, float, float] | None = None
    static_camera: bool | None = None
    joint_columns: tuple[str, ...] | None = None

    def joint_order(self, joint_names: list[str]) -> list[int]:
        """Column index of each of the robot's joints (a CSV of joints): by name, or ``j1..jn`` in
        the robot's order; :class:`FileFormatError` names what does not match."""
        columns = list(self.joint_columns or ())
        generic = [f"j{k + 1}" for k in range(len(joint_names))]
        if columns == generic:
            return list(range(len(columns)))
        if sorted(columns) != sorted(joint_names):
            raise FileFormatError(
                self.source,
                f"the joint columns {', '.join(columns)} are not the robot's joints ({', '.join(joint_names)}) nor "
                f"{', '.join(generic)}",
                "header",
            )
        return [columns.index(n) for n in joint_names]

    def read_image(self, view: PosedImage) -> np.ndarray:
        """The view's image, grey; :class:`FileFormatError` names the file when it is not an image."""
        return read_grey_image(view.image_path, self.source, view.name)

    def read_image_sized(self, view: PosedImage, size: tuple[int, int] | None) -> tuple[np.ndarray, tuple[int, int]]:
        """The view's image, grey, and its size (w, h) px, which must be ``size`` (the first image's) when given:
        one calibration is for one camera mode; :class:`FileFormatError` names the file that differs."""
        image = self.read_image(view)
        own = (image.shape[1], image.shape[0])
        if size is not None and own != size:
            raise FileFormatError(
                view.image_path,
                f"{own[0]} x {own[1]} px, the first image is {size[0]} x {size[1]} px: one calibration is for one "
                "camera mode",
            )
        return image, own


def load_posed_images(path: str | Path) -> PosedImages:
    """A ``cal_data.yaml`` or a ``.csv``, or a folder holding one (``cal_data.yaml``, else
    ``views.csv``): see the module's docstring."""
    path = Path(path)
    if path.is_dir():
        found = [path / name for name in ("cal_data.yaml", "views.csv") if (path / name).is_file()]
        if not found:
            raise FileFormatError(
                path,
                "a folder of views holds cal_data.yaml (ROS-Industrial's layout) or views.csv "
                "(image[,component],<joints>)",
            )
        path = found[0]
    if path.suffix.lower() == ".csv":
        return _load_csv(path)
    if path.suffix.lower() == ".json":
        return _load_json(path)
    return _load_cal_data(path)


ROTATION_TOLERANCE = 1e-3
"""How far from orthonormal (the largest element of R R^T - I) a pose file's rotation may be: controllers print
nine or so digits; a rotation further off is none, and is named."""


def _load_json(path: Path) -> PosedImages:
    import json

    text = read_text(path, "pose file (JSON)", 16 * 1024 * 1024)
    try:
        doc = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise FileFormatError(path, f"not JSON ({exc})") from None
    scale = 1000.0
    if isinstance(doc, dict):
        unit = doc.get("length_unit", "m")
        if unit not in ("m", "mm"):
            raise FileFormatError(path, f"must be 'm' or 'mm', got {unit!r}", "length_unit")
        scale = 1000.0 if unit == "m" else 1.0
        doc = doc.get("poses")
    if not isinstance(doc, list) or not 1 <= len(doc) <= MAX_VIEWS:
        raise FileFormatError(path, f"expected a list of 1 to {MAX_VIEWS} {{image, flange2base}} entries")
    views = []
    for k, entry in enumerate(doc):
        where = f"[{k}]"
        if not isinstance(entry, dict) or not isinstance(entry.get("image"), str) or not entry["image"].strip():
            raise FileFormatError(path, "expected an object with an image (a path) and flange2base", where)
        try:
            T = np.array(entry.get("flange2base"), dtype=float)
        except (TypeError, ValueError):
            raise FileFormatError(path, "expected a 4 x 4 matrix of numbers", f"{where}.flange2base") from None
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise FileFormatError(path, "expected a 4 x 4 matrix of finite numbers", f"{where}.flange2base")
        R = T[:3, :3]
        if (
            np.abs(R @ R.T - np.eye(3)).max() > ROTATION_TOLERANCE
            or np.linalg.det(R) <= 0
            or not np.allclose(T[3], [0, 0, 0, 1])
        ):
            raise FileFormatError(
                path,
                "not a rigid transform (its rotation is none, or its last row is not 0 0 0 1)",
                f"{where}.flange2base",
            )
        u, _, vt = np.linalg.svd(R)
        t_mm = T[:3, 3] * scale
        if np.abs(t_mm).max() > 1e5:
            raise FileFormatError(
                path, f"a translation of {np.abs(t_mm).max():.3g} mm: is the unit right?", f"{where}.flange2base"
            )
        image = entry["image"].strip()
        views.append(PosedImage(Path(image).stem, path.parent / image, flange2base=make_transform(u @ vt, t_mm)))
    return PosedImages(path, views)


def _quaternion_pose(values: dict, path: Path, where: str, scale_mm: float, keys: tuple[str, ...]) -> np.ndarray:
    missing = [k for k in keys if k not in values]
    if missing:
        raise FileFormatError(path, f"missing {', '.join(missing)} (a pose is {' '.join(keys)})", where)
    xyz = [finite_number(values[k], path, f"{where}.{k}") * scale_mm for k in keys[:3]]
    q = np.array([finite_number(values[k], path, f"{where}.{k}") for k in keys[3:]])
    norm = np.linalg.norm(q)
    if not 0.9 < norm < 1.1:
        raise FileFormatError(path, f"the quaternion (qx qy qz qw) has length {norm:.3f}, not 1: not a rotation", where)
    return make_transform(Rotation.from_quat(q / norm).as_matrix(), np.array(xyz))


def _board_from_target_finder(finder, path: Path) -> str:
    if not isinstance(finder, dict) or "type" not in finder:
        raise FileFormatError(path, "expected a mapping with a type", "target_finder")
    kind = finder["type"]

    def number(key):
        return finite_number(finder.get(key), path, f"target_finder.{key}", low=0.0, exclusive_low=True)

    def whole(key):
        value = finder.get(key)
        if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
            raise FileFormatError(path, f"must be a positive whole number, got {value!r}", f"target_finder.{key}")
        return value

    def dictionary():
        value = finder.get("dictionary")
        if isinstance(value, bool) or not isinstance(value, int) or value not in _ROS_DICTIONARIES:
            raise FileFormatError(path, f"not an OpenCV ArUco dictionary number: {value!r}", "target_finder.dictionary")
        return _ROS_DICTIONARIES[value]

    if kind == "CharucoGridTargetFinder":
        # ROS-Industrial builds CharucoBoard(cols, rows) with OpenCV before 4.6: the legacy layout.
        square_mm, marker_mm = 1000 * number("chessboard_dim"), 1000 * number("aruco_marker_dim")
        return f"charuco:{whole('cols')}x{whole('rows')}:{square_mm:g}:{marker_mm:g}:{dictionary()}:legacy"
    if kind == "ArucoGridTargetFinder":
        marker_mm, gap_mm = 1000 * number("aruco_marker_dim"), 1000 * number("aruco_marker_gap")
        return f"aruco:{whole('cols')}x{whole('rows')}:{marker_mm:g}:{gap_mm:g}:{dictionary()}"
    if kind == "ModifiedCircleGridTargetFinder":
        return f"circles:{whole('cols')}x{whole('rows')}:{1000 * number('spacing'):g}"
    raise FileFormatError(
        path,
        "videocal reads CharucoGridTargetFinder, ArucoGridTargetFinder and ModifiedCircleGridTargetFinder, not "
        f"{kind!r}",
        "target_finder.type",
    )


def _load_cal_data(path: Path) -> PosedImages:
    doc = read_yaml(path, "calibration data file", max_bytes=4 * 1024 * 1024)
    if not isinstance(doc, dict) or not isinstance(doc.get("data"), list):
        raise FileFormatError(path, "not a cal_data file: expected data: a list of {image, pose}", "data")
    if not doc["data"] or len(doc["data"]) > MAX_VIEWS:
        raise FileFormatError(path, f"expected 1 to {MAX_VIEWS} entries, got {len(doc['data'])}", "data")
    views = []
    for k, entry in enumerate(doc["data"]):
        where = f"data[{k}]"
        if (
            not isinstance(entry, dict)
            or not isinstance(entry.get("image"), str)
            or not isinstance(entry.get("pose"), str)
        ):
            raise FileFormatError(path, "expected {image: PATH, pose: PATH}", where)
        pose_path = path.parent / entry["pose"]
        pose = read_yaml(pose_path, "pose file", max_bytes=64 * 1024)
        if not isinstance(pose, dict):
            raise FileFormatError(pose_path, "expected x y z (m) and qx qy qz qw")
        flange2base = _quaternion_pose(pose, pose_path, "pose", 1000.0, ("x", "y", "z", "qx", "qy", "qz", "qw"))
        views.append(PosedImage(Path(entry["image"]).stem, path.parent / entry["image"], flange2base=flange2base))
    pinhole = None
    if "intrinsics" in doc:
        intr = doc["intrinsics"]
        if not isinstance(intr, dict):
            raise FileFormatError(path, "expected fx fy cx cy", "intrinsics")
        pinhole = tuple(
            finite_number(intr.get(k), path, f"intrinsics.{k}", low=0.0, exclusive_low=k in ("fx", "fy"))
            for k in ("fx", "fy", "cx", "cy")
        )
    static = doc.get("static_camera")
    if static is not None and not isinstance(static, bool):
        raise FileFormatError(path, f"must be true or false, got {static!r}", "static_camera")
    board = _board_from_target_finder(doc["target_finder"], path) if "target_finder" in doc else None
    return PosedImages(path, views, board, pinhole, static)


def _load_csv(path: Path) -> PosedImages:
    text = read_text(path, "calibration data CSV", 4 * 1024 * 1024)
    try:
        rows = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise FileFormatError(path, f"not a CSV file ({exc})") from None
    rows = [r for r in rows if r and any(c.strip() for c in r)]
    if not rows:
        raise FileFormatError(path, "empty: expected a header row (image, then a pose or the joints)")
    header = [c.strip() for c in rows[0]]
    if not header or header[0] != "image":
        raise FileFormatError(path, f"the first column must be 'image', got {header[0] if header else ''!r}", "header")
    columns = header[1:]
    if len(set(columns)) != len(columns):
        raise FileFormatError(path, "a column name appears twice", "header")
    named = bool(columns) and columns[0] == "component"
    if named:
        columns = columns[1:]
    elif "component" in columns:
        raise FileFormatError(path, "the component column must come right after image", "header")
    posed = set(columns) == set(POSE_COLUMNS)
    if not posed and (not columns or set(columns) & set(POSE_COLUMNS)):
        raise FileFormatError(path, f"expected the columns {', '.join(POSE_COLUMNS)} or one column per joint", "header")
    if posed and named:
        raise FileFormatError(
            path, "a component column goes with joint columns (a robot calibration), not with flange poses", "header"
        )
    if len(rows) - 1 > MAX_VIEWS or len(rows) < 2:
        raise FileFormatError(path, f"expected 1 to {MAX_VIEWS} rows of views, got {len(rows) - 1}")
    views = []
    for n, row in enumerate(rows[1:], start=2):
        where = f"row {n}"
        if len(row) != len(header):
            raise FileFormatError(path, f"{len(row)} values, the header has {len(header)}", where)
        image = row[0].strip()
        component = row[1].strip() or None if named else None
        cells = row[2:] if named else row[1:]
        if posed:
            numbers = dict(zip(columns, csv_numbers(cells, columns, path, where)))
            views.append(
                PosedImage(
                    Path(image).stem,
                    path.parent / image,
                    flange2base=_quaternion_pose(numbers, path, where, 1.0, POSE_COLUMNS),
                )
            )
        else:
            q = np.array(csv_numbers(cells, columns, path, where))
            views.append(PosedImage(Path(image).stem, path.parent / image, joints_deg=q, component=component))
    return PosedImages(path, views, joint_columns=None if posed else tuple(columns))
