"""Edits of the cell the operator core has open, as in the paper's RobCAD component and workcell
environments: components from mesh files, their placements, named features, task locations. Each
is an undoable command on the session's stack (:mod:`calib_core.workcell.edits`); ``save`` writes
them back into the workcell file. The core's events tell the views: ``scene_changed`` after a
component edit, ``task_changed(name)`` after a task location's."""

from __future__ import annotations

import numpy as np

from calib_core.errors import OperatorError
from calib_core.frames import transform_from_xyz_rpy
from calib_core.scene import SceneItem
from calib_core.workcell import TaskLocation
from calib_core.workcell.edits import AddComponent, AddFeature, AddTaskLocation, PlaceComponent, check_name, load_component_mesh
from calib_core.workcell.snapping import Snap, snap_point
from calib_core.workcell.writer import save_workcell


class CellEditor:
    """``dirty``: edits not yet saved to the workcell file."""

    def __init__(self, core):
        self.core = core
        self.dirty = False

    def _edited(self, kind: str, name: str) -> None:
        core = self.core
        core.cell.refresh_identity()
        self.dirty = True
        if kind == "task":
            if core.task is not None and core.task.name == name and name not in core.workcell.task_locations:
                core.task = None
            core.task_changed.emit(name)
        else:
            core.scene_version += 1
            core.scene_changed.emit()

    def add_task_location(self, name: str, tcp2base: np.ndarray | None = None, approach_mm: float = 0.0, component: str | None = None) -> TaskLocation:
        """A task location at ``tcp2base`` (4, 4) mm in base (default: the current TCP pose), for
        ``component`` (default: the current target). Undoable."""
        task = TaskLocation(str(name).strip(), self.core.model_tcp2base() if tcp2base is None else np.asarray(tcp2base, dtype=float), float(approach_mm), component or self.core.session.target)
        self.core.session.undo.push(AddTaskLocation(self.core.workcell, task, self._edited))
        return task

    def add_component(self, mesh_file, name: str, *, kind: str = "component", units: str = "mm", color=(0.7, 0.7, 0.7), item2world: np.ndarray | None = None) -> None:
        """A component from a mesh file, placed at ``item2world`` (default: 1 m in front of the robot). Undoable."""
        name = check_name(name, "component")
        if kind not in ("component", "fixture"):
            raise OperatorError(f"a component's kind is 'component' or 'fixture', got {kind!r}")
        mesh = load_component_mesh(mesh_file, units)
        placement = np.array(item2world, dtype=float) if item2world is not None else np.array([[1, 0, 0, 1000.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
        item = SceneItem(name, mesh, placement, tuple(float(c) for c in color), kind, {})
        self.core.session.undo.push(AddComponent(self.core.workcell, item, mesh_file, units, self._edited))

    def place_component(self, name: str, xyz_mm, rpy_deg) -> None:
        """Place a component by numbers (its surveyed placement: mm, deg, in base). Successive
        placements of one component are one undo step."""
        self.core.session.undo.push(PlaceComponent(self.core.workcell, name, transform_from_xyz_rpy(xyz_mm, rpy_deg), self._edited))

    def snap_feature(self, component: str, point_component_mm, radius_mm: float) -> Snap:
        """Where a click on ``component`` defines a feature (circle centre, corner, vertex or the surface point)."""
        return snap_point(self.core.workcell.component(component).mesh, point_component_mm, radius_mm)

    def add_feature(self, component: str, name: str, point_component_mm) -> None:
        """A named feature ``point_component_mm`` (3,) in the component's frame. Undoable."""
        self.core.session.undo.push(AddFeature(self.core.workcell, component, name, point_component_mm, self._edited))

    def save(self, path=None):
        """Write the edited cell back into its workcell YAML (comments and untouched entries kept)."""
        written = save_workcell(self.core.workcell, path)
        self.dirty = False
        self.core.message.emit(f"cell saved to {written}")
        return written
