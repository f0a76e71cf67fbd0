"""Collisions of the robot with itself and with the cell, from the URDF's collision meshes and the
cell's component meshes, with Pinocchio's collision checking (coal BVHs).

Which pairs are checked follows the practice of MoveIt's setup assistant: not two bodies on one
joint or on adjacent joints, and not a pair already in contact at the robot's home pose when
neither body can move away from the other (the base on its pedestal, two shells of one wrist).
A moving link touching the cell at home is not ignored: every move from there reports it.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from calib_core.robot.model import RobotModel, _to_se3
from calib_core.robot.visuals import geometry_model
from calib_core.scene import SceneItem
from calib_core.frames import concat

CELL_PREFIX = "cell/"


@dataclass(frozen=True)
class Contact:
    """Two bodies in contact: ``a`` a robot body (its geometry name), ``b`` another robot body or
    ``cell/<component>``."""

    a: str
    b: str

    @property
    def text(self) -> str:
        other = self.b[len(CELL_PREFIX) :] if self.b.startswith(CELL_PREFIX) else f"the robot's {self.b}"
        return f"{self.a} hits {other}"


def _bvh(mesh_mm) -> coal.BVHModelOBBRSS:
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(mesh_mm.faces), len(mesh_mm.vertices))
    bvh.addVertices(np.ascontiguousarray(np.asarray(mesh_mm.vertices, dtype=float) / 1000.0))
    bvh.addTriangles(np.ascontiguousarray(mesh_mm.faces, dtype=np.int64))
    bvh.endModel()
    return bvh


class CollisionWorld:
    """The robot's collision bodies and ``components`` (scene items in the base frame, mm), fixed in
    the cell. ``check(q)`` gives the contacts at joints ``q`` (deg/mm); ``ignored`` lists the pairs
    in contact at ``home_deg`` that cannot separate (never reported)."""

    def __init__(self, robot: RobotModel, components: list[SceneItem], home_deg: ArrayLike):
        self.robot = robot
        collision = geometry_model(robot, "collision")
        # A URDF without collision elements (many hand-written ones) is checked with its visual meshes.
        self.source = "collision" if collision.ngeoms else "visual"
        self.geometry = (collision if collision.ngeoms else geometry_model(robot, "visual")).copy()
        self._robot_ids = list(range(self.geometry.ngeoms))
        self._cell_ids = []
        for item in components:
            placement = _to_se3(concat(item.item2world, robot.base2root))  # the item in the URDF root
            obj = pin.GeometryObject(CELL_PREFIX + item.name, 0, 0, placement, _bvh(item.mesh))
            self._cell_ids.append(self.geometry.addGeometryObject(obj))
        self.ignored: list[Contact] = []
        self._pairs(home_deg)
        self._data = self.geometry.createData()

    def _joint_of(self, gid: int) -> int:
        return int(self.geometry.geometryObjects[gid].parentJoint)

    def _adjacent(self, ja: int, jb: int) -> bool:
        parents = self.robot.model.parents
        return ja == jb or int(parents[ja]) == jb or int(parents[jb]) == ja

    def _pairs(self, home_deg) -> None:
        candidates = []
        for i, a in enumerate(self._robot_ids):
            for b in self._robot_ids[i + 1 :]:
                if not self._adjacent(self._joint_of(a), self._joint_of(b)):
                    candidates.append((a, b))
        candidates += [(a, c) for a in self._robot_ids for c in self._cell_ids]
        for a, b in candidates:
            self.geometry.addCollisionPair(pin.CollisionPair(a, b))
        # Contacts at home between bodies that never move apart are part of the design, not collisions.
        data = self.geometry.createData()
        at_home = self._contacts(data, home_deg)
        keep = []
        for k, pair in enumerate(self.geometry.collisionPairs):
            a, b = int(pair.first), int(pair.second)
            ja, jb = self._joint_of(a), (self._joint_of(b) if b in self._robot_ids else 0)
            fixed_together = ja == 0 and jb == 0 if b in self._cell_ids else False
            if k in at_home and (fixed_together or b in self._robot_ids):
                self.ignored.append(self._contact(a, b))
            else:
                keep.append(pair)
        self.geometry.removeAllCollisionPairs()
        for pair in keep:
            self.geometry.addCollisionPair(pair)

    def _contacts(self, data, q_deg) -> set[int]:
        q = self.robot.configuration(q_deg)
        pin.computeCollisions(self.robot.model, self.robot.model.createData(), self.geometry, data, q, False)
        return {k for k, r in enumerate(data.collisionResults) if r.isCollision()}

    def _contact(self, a: int, b: int) -> Contact:
        names = self.geometry.geometryObjects
        return Contact(names[a].name, names[b].name)

    @property
    def pair_count(self) -> int:
        return len(self.geometry.collisionPairs)

    def check(self, q_deg: ArrayLike) -> list[Contact]:
        """Every checked pair in contact at ``q_deg``."""
        hits = self._contacts(self._data, q_deg)
        pairs = self.geometry.collisionPairs
        return [self._contact(int(pairs[k].first), int(pairs[k].second)) for k in sorted(hits)]
