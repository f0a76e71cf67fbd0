"""Where an overview camera looks to show a whole cell: its components and the robot, whatever the cell's size."""

from __future__ import annotations

import numpy as np

from calib_core.scene import SceneItem

HALF_VIEW_DEG = 20.0
"""Half the overview's vertical view angle (its 40 deg camera)."""


def world_corners(item: SceneItem) -> np.ndarray:
    """The 8 corners (8, 3) mm of ``item``'s mesh bounds in the world frame."""
    lo, hi = item.mesh.bounds
    box = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return (item.item2world @ box.T).T[:, :3]


def is_slab(item: SceneItem) -> bool:
    """A floor or a wall: far wider than it is thick (it does not count when framing the cell)."""
    extents = np.sort(item.mesh.extents)
    return bool(extents[0] < 0.05 * extents[2])


def cell_framing(items: list[SceneItem]) -> tuple[np.ndarray, float]:
    """``(target (3,) mm, distance mm)``: the centre of ``items``' bounds (slabs left out) and the distance at which
    a 40 deg camera shows them all, from any direction (clipped to 0.8-15 m)."""
    kept = [item for item in items if not is_slab(item)]
    corners = np.concatenate([world_corners(item) for item in kept]) if kept else np.zeros((1, 3))
    lo, hi = corners.min(axis=0), corners.max(axis=0)
    radius = max(float(np.linalg.norm(hi - lo)) / 2.0, 200.0)
    return (lo + hi) / 2.0, float(np.clip(1.1 * radius / np.sin(np.radians(HALF_VIEW_DEG)), 800.0, 15000.0))


def eye_at(target: np.ndarray, distance_mm: float, azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """The camera position (3,) mm ``distance_mm`` from ``target`` in the direction of ``azimuth_deg`` (about z, from
    x) and ``elevation_deg`` (above the x-y plane)."""
    a, e = np.radians(azimuth_deg), np.radians(elevation_deg)
    return np.asarray(target, float) + distance_mm * np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
