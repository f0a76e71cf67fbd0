"""What the renderer draws: a flat list of meshes with their poses.

The workcell and robot models produce scene items; the renderer consumes them. Neither
knows the other, which keeps VTK out of everything but ``calib_core/render``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import trimesh


@dataclass
class SceneItem:
    """One rigid mesh in the world (the robot base frame).

    ``name``: unique in a scene, e.g. ``"rack_a"`` or ``"robot/link3"``.
    ``mesh``: vertices in mm in the item's own frame.
    ``item2world``: (4, 4) pose, mm.
    ``color``: RGB in [0, 1].
    ``kind``: ``"component"`` (a workcell object that can be a calibration target),
    ``"robot"`` (a robot link, gripper or camera bracket) or ``"fixture"`` (floor, walls).
    ``features``: named feature points, (3,) mm each, in the item's own frame.
    ``feature_kinds``: the kind of each feature that is not a corner (circle, point), for Find points.
    ``texture``: an optional image (h, w) or (h, w, 3) uint8 printed on the mesh, with
    ``texture_coords`` (n_vertices, 2): per vertex (s, t) in [0, 1], s to the right and t up
    the image (OpenGL's convention). ``opacity`` in (0, 1].
    """

    name: str
    mesh: trimesh.Trimesh
    item2world: np.ndarray
    color: tuple[float, float, float] = (0.7, 0.7, 0.7)
    kind: str = "component"
    features: dict[str, np.ndarray] = field(default_factory=dict)
    feature_kinds: dict = field(default_factory=dict)
    texture: np.ndarray | None = None
    texture_coords: np.ndarray | None = None
    opacity: float = 1.0
    """Below 1: drawn see-through (a ghost robot of a previewed move)."""
    form_tolerance_mm: float = 0.0
    """How far the real part's features may lie from their CAD positions: 1-sigma per axis, mm (0: the part is its
    CAD). A look at the part carries it in its uncertainty (:mod:`calib_core.calibration.form_error`)."""
