"""What every calibration target's detector gives, and the detector settings an operator can tune.

A target (ChArUco, chessboard, circle grid, ArUco grid: see :func:`calib_core.vision.board.parse_board`)
detects itself in a grey image and returns a :class:`TargetDetection`: the image positions of the
points it found and their ids, which index the target's ``corners_mm()``.

The settings come from a YAML file (``--detector-params FILE``) with any of three sections, each
field named as OpenCV names it and checked against OpenCV's own parameter objects::

    refine_markers: true        # ChArUco and ArUco grids: recover markers the first pass missed
    aruco:                      # cv2.aruco.DetectorParameters
      adaptiveThreshWinSizeMax: 35
      cornerRefinementMethod: 1
    circle_blobs:               # cv2.SimpleBlobDetector_Params, for circle grids
      minArea: 25.0
      maxArea: 5000.0
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from calib_core.documents import read_yaml
from calib_core.errors import FileFormatError

SECTIONS = ("refine_markers", "aruco", "circle_blobs")


@dataclass(frozen=True)
class TargetDetection:
    """``corners_px`` (n, 2) float64 image positions, ``ids`` (n,) int indices into the target's
    ``corners_mm()``; ``markers_seen`` how many ArUco markers (or blobs) the detector saw, which
    tells "no target here" from "a target, but not enough of it"."""

    corners_px: np.ndarray
    ids: np.ndarray
    markers_seen: int = 0


def _aruco_defaults() -> cv2.aruco.DetectorParameters:
    return cv2.aruco.DetectorParameters()


def _blob_defaults() -> cv2.SimpleBlobDetector_Params:
    return cv2.SimpleBlobDetector_Params()


@dataclass
class DetectorSettings:
    """``aruco`` marker detection parameters, ``circle_blobs`` blob detection parameters (circle
    grids), ``refine_markers`` (on by default: on real images a first pass misses markers that the
    board's layout then finds; ROS-Industrial's ChArUco set loses 20 of 24 corners on one view without it)."""

    aruco: cv2.aruco.DetectorParameters = field(default_factory=_aruco_defaults)
    circle_blobs: cv2.SimpleBlobDetector_Params = field(default_factory=_blob_defaults)
    refine_markers: bool = True
    source: Path | None = None


def _set_fields(target, values, path: Path, section: str) -> None:
    if not isinstance(values, dict):
        raise FileFormatError(
            path, f"must be a mapping of parameter names to values, got {type(values).__name__}", section
        )
    known = sorted(n for n in dir(target) if not n.startswith("_") and not callable(getattr(target, n)))
    for name, value in values.items():
        where = f"{section}.{name}"
        if name not in known:
            raise FileFormatError(
                path, f"OpenCV has no such parameter; {section} parameters: {', '.join(known)}", where
            )
        current = getattr(target, name)
        if isinstance(current, bool):
            if not isinstance(value, bool):
                raise FileFormatError(path, f"must be true or false, got {value!r}", where)
        elif isinstance(current, int):
            if isinstance(value, bool) or not isinstance(value, int):
                raise FileFormatError(path, f"must be a whole number, got {value!r}", where)
        elif isinstance(current, float):
            try:  # (an integer past 2^63 made np.isfinite raise TypeError; one past 1e308 makes float() overflow)
                number = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None
            except OverflowError:
                number = None
            if number is None or not np.isfinite(number):
                raise FileFormatError(path, f"must be a finite number, got {str(value)[:40]}", where)
            value = number
        try:
            setattr(target, name, value)
        except (TypeError, ValueError, OverflowError, cv2.error) as exc:  # ValueError: "integer won't fit into a C int"
            raise FileFormatError(path, f"OpenCV refuses {value!r} ({exc})", where) from None


def load_detector_settings(path: str | Path) -> DetectorSettings:
    """Read a detector settings file (see the module's docstring); :class:`FileFormatError` names
    the file and the parameter for an unknown name or a value of the wrong kind."""
    path = Path(path)
    doc = read_yaml(path, "detector settings file", max_bytes=256 * 1024)
    if doc is None:
        doc = {}
    if not isinstance(doc, dict):
        raise FileFormatError(path, f"expected a mapping with any of {', '.join(SECTIONS)}")
    unknown = [k for k in doc if k not in SECTIONS]
    if unknown:
        raise FileFormatError(
            path, f"unknown section; a detector settings file has {', '.join(SECTIONS)}", str(unknown[0])
        )
    settings = DetectorSettings(source=path)
    if "refine_markers" in doc:
        if not isinstance(doc["refine_markers"], bool):
            raise FileFormatError(path, f"must be true or false, got {doc['refine_markers']!r}", "refine_markers")
        settings.refine_markers = doc["refine_markers"]
    if "aruco" in doc:
        _set_fields(settings.aruco, doc["aruco"], path, "aruco")
    if "circle_blobs" in doc:
        _set_fields(settings.circle_blobs, doc["circle_blobs"], path, "circle_blobs")
    return settings
