"""Edits of the cell the operator core has open, as in the paper's RobCAD component and workcell
environments: components from mesh files, their placements, named features, task locations. Each
is an undoable command on the session's stack (:mod:`calib_core.workcell.edits`); ``save`` writes
them back into the workcell file. The cell's and the task choice's events tell the views:
``scene_changed`` after a component edit, ``changed(name)`` after a task location's.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.editor``), given the cell, the session
(its undo stack and target), the task choice, the arm (where the TCP stands) and the log."""

from __future__ import annotations

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.errors import OperatorError
from calib_core.frames import transform_from_xyz_rpy
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.task_choice import TaskChoice
from calib_core.scene import SceneItem
from calib_core.workcell import TaskLocation
from calib_core.workcell.edits import (
    AddComponent,
    AddFeature,
    AddTaskLocation,
    CellEdit,
    PlaceComponent,
    SetTaskApproach,
    check_name,
    load_component_mesh,
)
from calib_core.workcell.snapping import Snap, snap_point
from calib_core.workcell.writer import save_workcell


class CellEditor:
    """``dirty``: edits not yet saved to the workcell file."""

    def __init__(self, cell: Cell, session: CalibrationSession, tasks: TaskChoice, arm: Arm, log: OperatorLog):
        self._cell, self._session, self._tasks, self._arm, self._log = cell, session, tasks, arm, log
        self.dirty = False
        session.undo.applied.connect(self._applied)

    def _applied(self, command) -> None:
        if not isinstance(command, CellEdit):
            return
        self._cell.refresh_identity()
        self.dirty = True
        if command.kind == "task":
            self._tasks.edited(command.name)
        else:
            self._cell.scene_edited()

    def set_task_approach(self, name: str, approach_mm: float) -> None:
        """Edit a task location's approach distance (mm): an undoable edit."""
        if abs(self._cell.workcell.task(name).approach_mm - approach_mm) < 1e-9:
            return
        self._session.undo.push(SetTaskApproach(self._cell.workcell, name, approach_mm))

    def add_task_location(
        self, name: str, tcp2base: np.ndarray | None = None, approach_mm: float = 0.0, component: str | None = None
    ) -> TaskLocation:
        """A task location at ``tcp2base`` (4, 4) mm in base (default: the current TCP pose), for
        ``component`` (default: the current target). Undoable."""
        task = TaskLocation(
            str(name).strip(),
            self._cell.robot.fk(self._arm.joints_deg, "tcp") if tcp2base is None else np.asarray(tcp2base, dtype=float),
            float(approach_mm),
            component or self._session.target,
        )
        self._session.undo.push(AddTaskLocation(self._cell.workcell, task))
        return task

    def add_component(
        self,
        mesh_file,
        name: str,
        *,
        kind: str = "component",
        units: str = "mm",
        color=(0.7, 0.7, 0.7),
        item2world: np.ndarray | None = None,
    ) -> None:
        """A component from a mesh file, placed at ``item2world`` (default: 1 m in front of the robot). Undoable."""
        name = check_name(name, "component")
        if kind not in ("component", "fixture"):
            raise OperatorError(f"a component's kind is 'component' or 'fixture', got {kind!r}")
        mesh = load_component_mesh(mesh_file, units)
        placement = (
            np.array(item2world, dtype=float)
            if item2world is not None
            else np.array([[1, 0, 0, 1000.0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
        )
        item = SceneItem(name, mesh, placement, tuple(float(c) for c in color), kind, {})
        self._session.undo.push(AddComponent(self._cell.workcell, item, mesh_file, units))

    def place_component(self, name: str, xyz_mm, rpy_deg) -> None:
        """Place a component by numbers (its surveyed placement: mm, deg, in base). Successive
        placements of one component are one undo step."""
        self._session.undo.push(PlaceComponent(self._cell.workcell, name, transform_from_xyz_rpy(xyz_mm, rpy_deg)))

    def snap_feature(self, component: str, point_component_mm, radius_mm: float) -> Snap:
        """Where a click on ``component`` defines a feature (circle centre, corner, vertex or the surface point)."""
        return snap_point(self._cell.workcell.component(component).mesh, point_component_mm, radius_mm)

    def add_feature(self, component: str, name: str, point_component_mm) -> None:
        """A named feature ``point_component_mm`` (3,) in the component's frame. Undoable."""
        self._session.undo.push(AddFeature(self._cell.workcell, component, name, point_component_mm))

    def save(self, path=None):
        """Write the edited cell back into its workcell YAML (comments and untouched entries kept)."""
        written = save_workcell(self._cell.workcell, path)
        self.dirty = False
        self._log.say(f"cell saved to {written}")
        return written
