"""What the camera saw at one robot pose, as the identification uses it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BOARD, CELL, OBJECT = "board", "cell", "object"


@dataclass(frozen=True)
class PoseView:
    """At commanded joints ``joints_deg`` (n,), points ``points_mm`` (m, 3) seen at ``pixels`` (m, 2).
    ``target``: :data:`BOARD` (the points are in the board's frame, whose placement in the cell is
    unknown and found with the robot) or :data:`CELL` (surveyed features, in the base frame)."""

    name: str
    joints_deg: np.ndarray
    points_mm: np.ndarray
    pixels: np.ndarray
    target: str = BOARD

    def __post_init__(self):
        if self.target not in (BOARD, CELL):
            raise ValueError(f"view {self.name}: target must be {BOARD!r} or {CELL!r}, got {self.target!r}")
        if self.points_mm.shape[0] != self.pixels.shape[0]:
            raise ValueError(f"view {self.name}: {len(self.points_mm)} points but {len(self.pixels)} pixels")


@dataclass(frozen=True)
class ObjectPoseView:
    """At commanded joints ``joints_deg`` (n,), a surveyed object measured at ``obj2cam`` (4, 4) mm
    with ``covariance`` (6, 6) of a left perturbation (rotation vector rad, then translation mm, in the
    camera frame: the model-based edge refinement's); the object stands at ``obj2base`` (4, 4) mm as
    surveyed. Its residual is the 6-vector that takes the predicted pose to the measured one,
    whitened by the covariance (the survey's own sigma added to the translation). ``points_mm``
    (m, 3), the object's own frame: points spread over it (its features), with which the pose is
    carried over to corrected intrinsics when the identification fits them (``None``: it is not)."""

    name: str
    joints_deg: np.ndarray
    obj2cam: np.ndarray
    covariance: np.ndarray
    obj2base: np.ndarray
    target: str = "object"
    points_mm: np.ndarray | None = None

    def __post_init__(self):
        c = np.asarray(self.covariance, dtype=float)
        if c.shape != (6, 6) or not np.all(np.isfinite(c)):
            raise ValueError(f"view {self.name}: the pose covariance must be a finite 6 x 6 matrix")
