"""The hand-eye file: ``cam2flange`` as xyz (mm) and rpy (deg) in YAML, with its 1-sigma, RMS and
warnings; what ``videocal calibrate-hand-eye`` and the window's Vision mode write, and what
``videocal gui --hand-eye`` reads."""

from __future__ import annotations

from pathlib import Path

import yaml

import numpy as np

from calib_core.atomic_file import atomic_write_text
from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy, xyz_rpy_from_transform
from calib_core.vision.hand_eye import HandEyeCalibration


def hand_eye_document(result: HandEyeCalibration) -> dict:
    xyz, rpy = xyz_rpy_from_transform(result.cam2flange)
    return {
        "cam2flange": {"xyz": [round(float(v), 4) for v in xyz], "rpy": [round(float(v), 5) for v in rpy]},
        "std": {"xyz_mm": [round(float(v), 4) for v in result.std_xyz_mm], "rotation_deg": [round(float(v), 5) for v in result.std_rotation_deg]},
        "units": {"length": "mm", "angle": "deg"},
        "rms_px": round(result.rms_px, 4),
        "poses": result.views,
        "warnings": list(result.warnings),
    }


def save_hand_eye(path: str | Path, result: HandEyeCalibration) -> None:
    """Write atomically (a crash leaves the old file whole)."""
    atomic_write_text(Path(path), yaml.safe_dump(hand_eye_document(result), sort_keys=False))


def load_cam2flange(path: str | Path) -> np.ndarray:
    """``cam2flange`` (4, 4) mm from a hand-eye file; ``FileFormatError`` names the file and what is wrong."""
    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text())
        pose = doc["cam2flange"]
        return transform_from_xyz_rpy(pose["xyz"], pose["rpy"])
    except FileNotFoundError:
        raise FileFormatError(path, "no such hand-eye file") from None
    except (yaml.YAMLError, KeyError, TypeError, ValueError) as exc:
        raise FileFormatError(path, f"not a cam2flange file: {exc}", "cam2flange") from None
