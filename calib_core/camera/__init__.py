"""The camera model: intrinsics, projection with lens distortion, intrinsics files."""

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import (
    distort_normalized,
    project,
    project_points,
    undistort_pixels,
    undistort_normalized,
    unproject,
)

__all__ = [
    "Intrinsics",
    "project",
    "project_points",
    "unproject",
    "undistort_pixels",
    "distort_normalized",
    "undistort_normalized",
]
