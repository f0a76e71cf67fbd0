"""Edits of the cell, as in the paper's RobCAD component and workcell environments: add a
component from a mesh file, place it by numbers (its surveyed placement), add named features,
add task locations, change a task's approach. Each is an undoable :class:`CellEdit` that names what it changed
(``kind``: ``component`` or ``task``, and the name); whoever keeps the cell in step listens to the undo stack's
``applied(command)`` event.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import trimesh

from calib_core.undo import Command
from calib_core.names import check_typed_name
from calib_core.errors import OperatorError
from calib_core.frames import check_transform
from calib_core.mesh_files import MESH_SCALE, load_mesh
from calib_core.scene import SceneItem
from calib_core.workcell.model import TaskLocation, Workcell


class CellEdit(Command):
    """An edit of the cell: ``kind`` (``component`` or ``task``) and ``name`` say what it changed."""

    kind = "component"
    name = ""


def check_name(name: str, what: str) -> str:
    """A name typed in the window (:func:`calib_core.names.check_typed_name`)."""
    return check_typed_name(name, what)


def load_component_mesh(path: str | Path, units: str = "mm") -> trimesh.Trimesh:
    """A component's mesh (mm) from a file; :class:`FileFormatError` names the file
    (:func:`calib_core.mesh_files.load_mesh`)."""
    if units not in MESH_SCALE:
        raise OperatorError(f"mesh units must be one of {', '.join(MESH_SCALE)}, got {units!r}")
    return load_mesh(path, units)


class AddComponent(CellEdit):
    def __init__(self, workcell: Workcell, item: SceneItem, mesh_file: Path, mesh_units: str):
        if any(c.name == item.name for c in workcell.components):
            raise OperatorError(f"the cell has a component called {item.name!r} already")
        self.workcell, self.item, self.name = workcell, item, item.name
        self.source = (Path(mesh_file).resolve(), mesh_units)
        self.label = f"Add component {item.name}"

    def do(self) -> None:
        self.workcell.components.append(self.item)
        self.workcell.meta.setdefault("mesh_files", {})[self.item.name] = self.source

    def undo(self) -> None:
        self.workcell.components.remove(self.item)
        self.workcell.meta["mesh_files"].pop(self.item.name, None)


class PlaceComponent(CellEdit):
    """Move a component to ``item2world`` (4, 4) mm in base. Successive placements of one component
    (a spin box being turned) merge into one undo step."""

    def __init__(self, workcell: Workcell, name: str, item2world: np.ndarray):
        self.item, self.name = workcell.component(name), name
        self.old = self.item.item2world.copy()
        self.new = check_transform(item2world, name=f"placement of {name}")
        self.label = f"Place {name}"

    def do(self) -> None:
        self.item.item2world = self.new.copy()

    def undo(self) -> None:
        self.item.item2world = self.old.copy()

    def merge(self, later: Command) -> bool:
        if isinstance(later, PlaceComponent) and later.item is self.item:
            self.new = later.new
            return True
        return False


class AddFeature(CellEdit):
    """A named feature point ``point_mm`` (3,) in the component's own frame."""

    def __init__(self, workcell: Workcell, component: str, name: str, point_mm):
        self.item, self.name = workcell.component(component), component
        self.feature = check_name(name, "feature")
        if self.feature in self.item.features:
            raise OperatorError(f"component {component!r} has a feature called {self.feature!r} already")
        point = np.asarray(point_mm, dtype=float).reshape(3)
        if not np.all(np.isfinite(point)):
            raise OperatorError(f"feature {self.feature!r}: the point must be finite, got {point.tolist()}")
        self.point = point
        self.label = f"Add feature {component}/{self.feature}"

    def do(self) -> None:
        self.item.features[self.feature] = self.point.copy()

    def undo(self) -> None:
        self.item.features.pop(self.feature, None)


class AddTaskLocation(CellEdit):
    kind = "task"

    def __init__(self, workcell: Workcell, task: TaskLocation):
        check_name(task.name, "task location")
        if task.name in workcell.task_locations:
            raise OperatorError(f"there is already a task location called {task.name!r}")
        if not np.isfinite(task.approach_mm) or task.approach_mm < 0:
            raise OperatorError(f"task location {task.name!r}: the approach must be >= 0 mm, got {task.approach_mm}")
        if task.component is not None:
            workcell.component(task.component)
        check_transform(task.tcp2base, name=f"task location {task.name}")
        self.workcell, self.task, self.name = workcell, task, task.name
        self.label = f"Add task location {task.name}"

    def do(self) -> None:
        self.workcell.task_locations[self.task.name] = self.task

    def undo(self) -> None:
        self.workcell.task_locations.pop(self.task.name, None)


class SetTaskApproach(CellEdit):
    """Change a task location's approach distance (mm back along the tool's z axis)."""

    kind = "task"

    def __init__(self, workcell: Workcell, name: str, approach_mm: float):
        if not np.isfinite(approach_mm) or approach_mm < 0:
            raise OperatorError(f"the approach of {name} must be >= 0 mm, got {approach_mm}")
        self.tasks, self.name = workcell.task_locations, name
        self.new, self.old = float(approach_mm), float(workcell.task(name).approach_mm)
        self.label = f"Approach of {name} {self.old:g} -> {self.new:g} mm"

    def _set(self, value: float) -> None:
        self.tasks[self.name] = replace(self.tasks[self.name], approach_mm=value)

    def do(self) -> None:
        self._set(self.new)

    def undo(self) -> None:
        self._set(self.old)
