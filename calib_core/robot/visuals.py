"""The robot's visual geometry as scene items, posed at given joints.

Pinocchio reads the URDF's visual primitives (boxes, cylinders) with their colours; they are
turned into trimesh meshes once, and only their poses change with the joints.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin
import trimesh
from numpy.typing import ArrayLike

from calib_core.robot.model import RobotModel, _to_mm
from calib_core.scene import SceneItem

_CYLINDER_SECTIONS = 32


def _mesh_of(geometry) -> trimesh.Trimesh:
    """A trimesh (mm) of a coal primitive (m) in its own frame."""
    if isinstance(geometry, coal.Box):
        return trimesh.creation.box(extents=2000.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return trimesh.creation.cylinder(radius=1000.0 * geometry.radius, height=2000.0 * geometry.halfLength, sections=_CYLINDER_SECTIONS)
    if isinstance(geometry, coal.Sphere):
        return trimesh.creation.icosphere(radius=1000.0 * geometry.radius, subdivisions=2)
    raise ValueError(f"robot visual of type {type(geometry).__name__} is not supported (use boxes, cylinders or spheres)")


@dataclass
class RobotVisuals:
    """The robot's visual meshes; :meth:`scene_items` poses them at joints ``q_deg``."""

    robot: RobotModel
    geometry_model: pin.GeometryModel
    meshes: list[trimesh.Trimesh]

    @classmethod
    def from_robot(cls, robot: RobotModel) -> RobotVisuals:
        gm = pin.buildGeomFromUrdf(robot.model, str(robot.urdf_path), pin.GeometryType.VISUAL)
        return cls(robot, gm, [_mesh_of(g.geometry) for g in gm.geometryObjects])

    def poses(self, q_deg: ArrayLike) -> list[np.ndarray]:
        """``visual2base`` (4, 4) mm of every visual at ``q_deg``."""
        q = np.radians(self.robot.check_joints(q_deg))
        data = self.geometry_model.createData()
        pin.updateGeometryPlacements(self.robot.model, self.robot.data, self.geometry_model, data, q)
        return [_to_mm(p) for p in data.oMg]

    def scene_items(self, q_deg: ArrayLike) -> list[SceneItem]:
        """One :class:`SceneItem` per visual, named ``robot/<link>_<index>``, kind ``robot``."""
        items = []
        for i, (g, mesh, pose) in enumerate(zip(self.geometry_model.geometryObjects, self.meshes, self.poses(q_deg))):
            color = tuple(float(c) for c in np.asarray(g.meshColor)[:3])
            items.append(SceneItem(name=f"robot/{g.name}", mesh=mesh, item2world=pose, color=color, kind="robot"))
        return items
