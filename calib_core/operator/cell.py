"""The cell the operator opened: its workcell, its robot model, its camera model, and how its
controller numbers the joints, with what is put up in it for a while (a calibration board).
Everything the core knows about the world comes from here (and from the devices); nothing here is
simulated. Its events say which of its parts changed: ``camera_model_changed()`` (the intrinsics,
the camera mounting or the robot's placements), ``scene_changed()`` (components, what is put up).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np
from psygnal import Signal

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.errors import VideocalError
from calib_core.connectors.joint_map import JointMap
from calib_core.robot.collision import CollisionWorld
from calib_core.robot.model import RobotModel
from calib_core.robot.visuals import RobotVisuals
from calib_core.scene import SceneItem
from calib_core.workcell import DEFAULT_WORKCELL, Workcell, load_workcell


@dataclass(frozen=True)
class CellIdentity:
    """Which cell a workspace or recording belongs to: its ``name`` and a ``content_hash``
    (sha256, hex) of what a correction depends on: the robot description as resolved (URDF and
    frames), the joints, and every component's mesh file, placement and features."""

    name: str
    content_hash: str

    def to_dict(self) -> dict:
        return {"name": self.name, "content_hash": self.content_hash}


def cell_identity(workcell: Workcell, robot: RobotModel) -> CellIdentity:
    h = hashlib.sha256()
    h.update(robot.urdf_xml.encode())
    spec = workcell.robot_spec
    roles = {
        role: robot.frame_placement(role).round(6).tolist() + [robot.roles[role]]
        for role in robot.roles
        if role != "base"
    }
    h.update(
        json.dumps(
            {"roles": roles, "base": robot.roles.get("base"), "held": spec.held_joints, "joints": robot.joint_names},
            sort_keys=True,
        ).encode()
    )
    for item in workcell.components:
        h.update(item.name.encode())
        h.update(np.round(item.item2world, 6).tobytes())
        h.update(json.dumps({k: np.round(v, 6).tolist() for k, v in sorted(item.features.items())}).encode())
        h.update(np.round(np.asarray(item.mesh.vertices), 4).tobytes())
    return CellIdentity(workcell.name, h.hexdigest())


class CellMismatchError(VideocalError, ValueError):
    """A file made on another cell than the one open."""


@dataclass
class Cell:
    """``workcell``; ``robot``: the model robot (its camera mounting may be replaced by a
    measured one); ``intrinsics``: the camera model in use; ``joint_map``: model joints to
    controller axes; ``identity``: see :class:`CellIdentity`; ``extras``: things put into the cell for a
    while (a calibration board), drawn in the CAD views and avoided by moves; ``scene_version`` counts the
    changes of what the CAD views show."""

    camera_model_changed: ClassVar[Signal] = Signal()
    scene_changed: ClassVar[Signal] = Signal()

    workcell: Workcell
    robot: RobotModel
    intrinsics: Intrinsics
    joint_map: JointMap
    identity: CellIdentity
    extras: list[SceneItem] = field(default_factory=list)
    scene_version: int = 0
    _visuals: RobotVisuals | None = field(default=None, repr=False)
    _collision: tuple[int, CollisionWorld] | None = field(default=None, repr=False)

    @classmethod
    def from_workcell(cls, workcell: Workcell, intrinsics: Intrinsics | None = None) -> Cell:
        robot = workcell.load_robot()
        if intrinsics is None:
            if workcell.intrinsics_path is None:
                raise VideocalError(
                    f"{workcell.path}: the workcell names no camera file (camera.intrinsics): calibrate the camera "
                    "first (videocal calibrate-intrinsics)"
                )
            intrinsics = load_intrinsics(workcell.intrinsics_path)
        return cls(
            workcell,
            robot,
            intrinsics,
            JointMap.for_robot(robot.joint_names, workcell.robot_spec.controller),
            cell_identity(workcell, robot),
        )

    @classmethod
    def open(cls, path: str | Path = DEFAULT_WORKCELL, intrinsics: Intrinsics | None = None) -> Cell:
        """Load the workcell file at ``path`` and its robot; errors name the file and field."""
        return cls.from_workcell(load_workcell(path), intrinsics)

    @property
    def name(self) -> str:
        return self.workcell.name

    @property
    def home_joints(self) -> np.ndarray:
        """(n,) deg/mm, model joint order."""
        return np.array(self.workcell.home_joints_deg, dtype=float)

    def refresh_identity(self) -> None:
        """After an edit of the cell: its identity follows its content."""
        self.identity = cell_identity(self.workcell, self.robot)

    def use_intrinsics(self, intrinsics: Intrinsics) -> None:
        """Picks, solves and the virtual camera use ``intrinsics`` from now on (any size: a replay uses
        the recording's camera while it plays)."""
        if intrinsics != self.intrinsics:
            self.intrinsics = intrinsics
            self.camera_model_changed.emit()

    def put_up(self, extras: list[SceneItem]) -> None:
        """Put ``extras`` into the cell in place of what was put up before (``[]``: take it down)."""
        self.extras = list(extras)
        self.scene_edited()

    def robot_edited(self) -> None:
        """The robot's placements changed in place (a calibration applied or reverted, a measured tool):
        the camera the views model and the bodies moves are checked against."""
        self.scene_version += 1
        self.camera_model_changed.emit()
        self.scene_changed.emit()

    def scene_edited(self) -> None:
        """What the CAD views show changed (a component edited, something put up)."""
        self.scene_version += 1
        self.scene_changed.emit()

    def collision_world(self) -> CollisionWorld:
        """The robot's collision bodies and the cell's components with what is put up in it, built again
        only after the scene changed."""
        if self._collision is None or self._collision[0] != self.scene_version:
            self._collision = (
                self.scene_version,
                CollisionWorld(self.robot, list(self.workcell.components) + list(self.extras), self.home_joints),
            )
        return self._collision[1]

    def model_visuals(self) -> RobotVisuals:
        """The modelled robot's meshes (loaded once)."""
        if self._visuals is None:
            self._visuals = RobotVisuals.from_robot(self.robot)
        return self._visuals

    def check_identity(self, other: dict | None, what: str) -> None:
        """Refuse a file (``what``) made on another cell; ``other`` is its recorded identity
        (``None``: an old file that recorded none, accepted by name of its workcell)."""
        if other is None:
            return
        if other.get("content_hash") != self.identity.content_hash:
            raise CellMismatchError(
                f"{what} belongs to the cell {other.get('name')!r} (content {str(other.get('content_hash'))[:12]}), "
                f"the open cell is {self.name!r} (content {self.identity.content_hash[:12]}): open its cell first "
                "(File > Open cell)"
            )
