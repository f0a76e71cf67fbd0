"""The robot's geometry (visual or collision) as scene items, posed at given joints.

Pinocchio reads the URDF's geometry (boxes, cylinders, spheres, and meshes in STL, OBJ, DAE,
glTF through coal's loader) with its colours and placements; each shape becomes a trimesh mesh
in mm once (meshes are cached by file), and only the poses change with the joints.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin
import trimesh
from numpy.typing import ArrayLike

from calib_core.errors import FileFormatError
from calib_core.robot import mesh_cache
from calib_core.robot.model import RobotModel, _to_mm
from calib_core.scene import SceneItem
from calib_core.frames import concat, invert

_CYLINDER_SECTIONS = 32
_KINDS = {"visual": pin.GeometryType.VISUAL, "collision": pin.GeometryType.COLLISION}


def _bvh_arrays(geometry) -> tuple[np.ndarray, np.ndarray]:
    vertices = np.ascontiguousarray(geometry.vertices(), dtype=float)
    triangles = np.empty((geometry.num_tris, 3), dtype=np.int64)
    for i in range(geometry.num_tris):
        t = geometry.tri_indices(i)
        triangles[i] = (t[0], t[1], t[2])
    return vertices, triangles


_MESH_CACHE: dict[tuple, trimesh.Trimesh] = {}


def _mesh_of(g: pin.GeometryObject, where: str) -> trimesh.Trimesh:
    """A trimesh (mm) of a coal shape (m) in its own frame."""
    geometry = g.geometry
    if isinstance(geometry, coal.Box):
        return trimesh.creation.box(extents=2000.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Cylinder):
        return trimesh.creation.cylinder(
            radius=1000.0 * geometry.radius, height=2000.0 * geometry.halfLength, sections=_CYLINDER_SECTIONS
        )
    if isinstance(geometry, coal.Sphere):
        return trimesh.creation.icosphere(radius=1000.0 * geometry.radius, subdivisions=2)
    if isinstance(geometry, coal.Capsule):
        return trimesh.creation.capsule(radius=1000.0 * geometry.radius, height=2000.0 * geometry.halfLength)
    if isinstance(geometry, coal.BVHModelBase):
        key = (g.meshPath, tuple(np.round(np.asarray(g.meshScale), 9)))
        if key not in _MESH_CACHE:
            vertices, triangles = _bvh_arrays(geometry)
            if len(triangles) == 0:
                raise FileFormatError(g.meshPath, f"{where}: the mesh has no triangles")
            _MESH_CACHE[key] = trimesh.Trimesh(vertices * 1000.0, triangles, process=False)
        return _MESH_CACHE[key]
    raise FileFormatError(
        g.meshPath or "(URDF)",
        f"{where}: geometry of type {type(geometry).__name__} is not supported (use meshes, boxes, cylinders, spheres "
        "or capsules)",
    )


_GEOMETRY_CACHE: dict[tuple, pin.GeometryModel] = {}


def geometry_model(robot: RobotModel, kind: str = "visual") -> pin.GeometryModel:
    """Pinocchio's geometry model of ``kind`` (``visual`` or ``collision``) for ``robot``'s
    driven joints; :class:`FileFormatError` names the URDF when a mesh cannot be read.

    Shapes are placed on their parent joints, so one model serves every copy of a robot (the
    modelled and the true one of the simulated site): it is built once per description and
    never modified (each pose computation makes its own data)."""
    key = (
        hash(robot.urdf_xml),
        str(robot.urdf_path),
        kind,
        robot.locked_joint_ids,
        None if robot.locked_configuration is None else robot.locked_configuration.tobytes(),
    )
    if key not in _GEOMETRY_CACHE:
        _GEOMETRY_CACHE[key] = _build_geometry_model(robot, kind)
    return _GEOMETRY_CACHE[key]


_CACHED_MESHES: dict[int, dict[str, trimesh.Trimesh]] = {}  # id(geometry model) -> meshes from the disk cache


def _build_geometry_model(robot: RobotModel, kind: str) -> pin.GeometryModel:
    full = robot.full_model if robot.full_model is not None else robot.model
    placeholder = (
        mesh_cache.placeholder_description(robot.urdf_xml, kind) if robot.urdf_xml and kind == "visual" else None
    )
    xml = placeholder[0] if placeholder else robot.urdf_xml
    try:
        gm = (
            pin.buildGeomFromUrdfString(full, xml, _KINDS[kind])
            if xml
            else pin.buildGeomFromUrdf(full, str(robot.urdf_path), _KINDS[kind])
        )
    except (RuntimeError, ValueError) as exc:
        raise FileFormatError(robot.urdf_path, f"cannot read the robot's {kind} geometry: {exc}") from None
    if robot.locked_joint_ids:
        _, (gm,) = pin.buildReducedModel(full, [gm], list(robot.locked_joint_ids), robot.locked_configuration)
    if placeholder:
        _CACHED_MESHES[id(gm)] = placeholder[1]
    return gm


@dataclass
class RobotVisuals:
    """The robot's meshes; :meth:`scene_items` poses them at joints ``q_deg`` in the base frame."""

    robot: RobotModel
    geometry_model: pin.GeometryModel
    meshes: list[trimesh.Trimesh]

    @classmethod
    def from_robot(cls, robot: RobotModel, kind: str = "visual") -> RobotVisuals:
        gm = geometry_model(robot, kind)
        cached = _CACHED_MESHES.get(id(gm), {})
        meshes = []
        for g in gm.geometryObjects:
            mesh = cached.get(g.name)
            if mesh is None:
                mesh = _mesh_of(g, f"link geometry '{g.name}'")
                if kind == "visual" and isinstance(g.geometry, coal.BVHModelBase):
                    mesh_cache.store(g.meshPath, tuple(np.asarray(g.meshScale)), mesh)
            meshes.append(mesh)
        return cls(robot, gm, meshes)

    def poses(self, q_deg: ArrayLike) -> list[np.ndarray]:
        """``visual2base`` (4, 4) mm of every visual at ``q_deg``."""
        q = self.robot.configuration(q_deg)
        data = self.geometry_model.createData()
        pin.updateGeometryPlacements(self.robot.model, self.robot.data, self.geometry_model, data, q)
        root2base = invert(self.robot.base2root)
        return [concat(_to_mm(p), root2base) for p in data.oMg]

    def riding_with(self, frame: str) -> frozenset[str]:
        """The names of the scene items (:meth:`scene_items`) on the joint that carries ``frame`` (the
        gripper and its fingers with a camera on the flange): they move with that frame."""
        joint = self.robot.model.frames[self.robot.frame_id(frame)].parentJoint
        return frozenset(f"robot/{g.name}" for g in self.geometry_model.geometryObjects if g.parentJoint == joint)

    def scene_items(self, q_deg: ArrayLike) -> list[SceneItem]:
        """One :class:`SceneItem` per visual, named ``robot/<link>_<index>``, kind ``robot``."""
        items = []
        for g, mesh, pose in zip(self.geometry_model.geometryObjects, self.meshes, self.poses(q_deg)):
            color = tuple(float(c) for c in np.asarray(g.meshColor)[:3])
            items.append(SceneItem(name=f"robot/{g.name}", mesh=mesh, item2world=pose, color=color, kind="robot"))
        return items
