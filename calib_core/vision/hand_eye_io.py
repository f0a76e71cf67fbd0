"""The hand-eye file: ``cam2flange`` as xyz (mm) and rpy (deg) in YAML, with its 1-sigma, RMS and
warnings; what ``videocal calibrate-hand-eye`` and the window's Vision mode write, and what
``videocal gui --hand-eye`` reads."""

from __future__ import annotations

from pathlib import Path

import yaml

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.atomic_file import atomic_write_text
from calib_core.documents import finite_number, read_yaml
from calib_core.errors import FileFormatError
from calib_core.frames import make_transform, transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.vision.hand_eye import HandEyeCalibration


def hand_eye_document(result: HandEyeCalibration) -> dict:
    """``cam2flange`` (a camera on the robot) or ``cam2base`` (a static camera) with the board's
    placement, ``board2base`` or ``board2flange``, all as xyz (mm) and rpy (deg)."""
    xyz, rpy = xyz_rpy_from_transform(result.camera2mount)
    bxyz, brpy = xyz_rpy_from_transform(result.board2mount)
    camera, board = ("cam2base", "board2flange") if result.static_camera else ("cam2flange", "board2base")
    return {
        camera: {"xyz": [round(float(v), 4) for v in xyz], "rpy": [round(float(v), 5) for v in rpy]},
        board: {"xyz": [round(float(v), 4) for v in bxyz], "rpy": [round(float(v), 5) for v in brpy]},
        "std": {
            "xyz_mm": [round(float(v), 4) for v in result.std_xyz_mm],
            "rotation_deg": [round(float(v), 5) for v in result.std_rotation_deg],
        },
        "units": {"length": "mm", "angle": "deg"},
        "rms_px": round(result.rms_px, 4),
        "corner_noise_px": round(float(result.noise_px), 4),
        "poses": result.views,
        "warnings": list(result.warnings),
    }


def save_hand_eye(path: str | Path, result: HandEyeCalibration) -> None:
    """Write atomically (a crash leaves the old file whole)."""
    atomic_write_text(Path(path), yaml.safe_dump(hand_eye_document(result), sort_keys=False))


def load_mounting(path: str | Path) -> tuple[np.ndarray, str | None]:
    """(``cam2frame`` (4, 4) mm, the frame it is on, or ``None`` for the cell's flange): a hand-eye file
    (:func:`load_cam2flange`), or a ``static_transform_publisher`` launch file (MoveIt 2's hand-eye calibration, an
    XML launch, videocal's own: :mod:`calib_core.ros2.mounting_in`) whose child frame must be an optical frame
    (z along the view, as videocal's camera frame): a ``camera_link`` (x forward) would turn the view 90 deg."""
    from calib_core.ros2.mounting_in import is_launch_file, read_static_transform

    if not is_launch_file(path):
        return _plausible(load_cam2flange(path), path, "cam2flange.xyz"), None
    found = read_static_transform(path)
    if "optical" not in found.child.lower():
        raise FileFormatError(
            path,
            f"the camera frame {found.child!r} is not an optical frame (z along the view, x right, y down): "
            "give the transform to the camera's *_optical_frame",
            "arguments",
        )
    return _plausible(found.child2parent_mm, path, "arguments"), found.parent


MAX_MOUNTING_MM = 3000.0
"""The farthest a camera on the robot may be from the frame it is mounted on (mm): an arm's reach."""


def _plausible(cam2frame: np.ndarray, path, field: str) -> np.ndarray:
    distance = float(np.linalg.norm(cam2frame[:3, 3]))
    if distance > MAX_MOUNTING_MM:
        raise FileFormatError(
            path,
            f"the camera would be {distance:.0f} mm from the frame it is mounted on, beyond {MAX_MOUNTING_MM:g} mm: "
            "a camera on the robot is within an arm's reach of its flange (are the units mm?)",
            field,
        )
    return cam2frame


def load_cam2flange(path: str | Path) -> np.ndarray:
    """``cam2flange`` (4, 4) mm from a hand-eye file; ``FileFormatError`` names the file and the field.

    ``cam2flange.xyz`` (mm) and ``cam2flange.rpy`` (deg) are three finite numbers each; a ``units``
    section, when there is one, must say mm and deg (a file in metres would put the camera a thousand
    times too close). easy_handeye2's ``.calib`` (an ``eye_in_hand`` calibration) is read too."""
    path = Path(path)
    doc = read_yaml(path, "hand-eye file", max_bytes=1024 * 1024)
    if isinstance(doc, dict) and isinstance(doc.get("parameters"), dict) and "transform" in doc:
        return _easy_handeye2(path, doc)
    if isinstance(doc, dict) and "cam2base" in doc and "cam2flange" not in doc:
        raise FileFormatError(
            path,
            "this is a static camera's calibration (cam2base): the camera is not on the robot's flange",
            "cam2base",
        )
    if not isinstance(doc, dict) or not isinstance(doc.get("cam2flange"), dict):
        raise FileFormatError(
            path, "not a hand-eye file: expected a cam2flange section with xyz (mm) and rpy (deg)", "cam2flange"
        )
    units = doc.get("units")
    if units is not None:
        if not isinstance(units, dict) or units.get("length", "mm") != "mm" or units.get("angle", "deg") != "deg":
            raise FileFormatError(path, f"videocal reads cam2flange in mm and deg, the file says {units!r}", "units")
    pose = doc["cam2flange"]
    values = {}
    for key in ("xyz", "rpy"):
        v = pose.get(key)
        if not isinstance(v, list) or len(v) != 3:
            raise FileFormatError(path, f"must be a list of 3 numbers, got {v!r}", f"cam2flange.{key}")
        values[key] = [finite_number(x, path, f"cam2flange.{key}[{i}]") for i, x in enumerate(v)]
    return transform_from_xyz_rpy(values["xyz"], values["rpy"])


def _easy_handeye2(path: Path, doc: dict) -> np.ndarray:
    """easy_handeye2's ``.calib``: ``transform`` is the tracking frame (the camera) in the robot's effector frame,
    metres
    and a unit quaternion (x, y, z, w), as its publisher puts it on tf. Only an ``eye_in_hand`` calibration is a
    camera mounting on the flange; the tracking frame is taken as the camera's optical frame (z along the axis)."""
    kind = doc["parameters"].get("calibration_type")
    if kind != "eye_in_hand":
        raise FileFormatError(
            path,
            f"an easy_handeye2 calibration of type {kind!r}: only eye_in_hand is a camera on the robot's flange",
            "parameters.calibration_type",
        )
    transform = doc.get("transform")
    if (
        not isinstance(transform, dict)
        or not isinstance(transform.get("translation"), dict)
        or not isinstance(transform.get("rotation"), dict)
    ):
        raise FileFormatError(
            path, "expected transform.translation {x, y, z} (m) and transform.rotation {x, y, z, w}", "transform"
        )
    t = [finite_number(transform["translation"].get(k), path, f"transform.translation.{k}") for k in "xyz"]
    q = np.array([finite_number(transform["rotation"].get(k), path, f"transform.rotation.{k}") for k in "xyzw"])
    if abs(np.linalg.norm(q) - 1.0) > 1e-3:
        raise FileFormatError(path, f"not a unit quaternion (norm {np.linalg.norm(q):.4f})", "transform.rotation")
    return make_transform(Rotation.from_quat(q / np.linalg.norm(q)).as_matrix(), np.array(t) * 1000.0)
