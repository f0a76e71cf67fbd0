"""What the camera saw at one robot pose, as the identification uses it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BOARD, CELL = "board", "cell"


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
