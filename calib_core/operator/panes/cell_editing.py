"""The cell panel's model: the cell's components, their placements and features, its task locations, as edited."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.cell_editor import CellEditor
from calib_core.operator.operator_log import OperatorLog


class CellPaneModel:
    """What the cell panel shows and edits: the components (their placements and features), the task locations, the
    cell file; every edit an undoable command of the cell's editor. Event: ``scene_changed()`` (the cell's own).

    Its public members: the event, five values shown (``component_names``, ``component(name)``, ``target``,
    ``cell_folder``, ``tcp2base``) and the editor's six edits the panel offers."""

    def __init__(self, cell: Cell, editor: CellEditor, session: CalibrationSession, arm: Arm, log: OperatorLog):
        self._cell, self._editor, self._session, self._arm, self._log = cell, editor, session, arm, log
        self.scene_changed = cell.scene_changed

    @property
    def component_names(self) -> list[str]:
        return [c.name for c in self._cell.workcell.components]

    def component(self, name: str):
        """The component ``name`` (a SceneItem: ``item2world`` (4, 4) mm in base, ``features`` mm in its frame)."""
        return self._cell.workcell.component(name)

    @property
    def target(self) -> str | None:
        return self._session.target

    @property
    def cell_folder(self) -> Path:
        return self._cell.workcell.path.parent

    @property
    def tcp2base(self) -> np.ndarray:
        """The model's TCP (4, 4) mm in base at the arm's joints now."""
        return self._cell.robot.fk(self._arm.joints_deg, "tcp")

    def place_component(self, name: str, xyz_mm, rpy_deg) -> None:
        self._editor.place_component(name, xyz_mm, rpy_deg)

    def add_component(self, mesh_file, name: str) -> None:
        self._editor.add_component(mesh_file, name)

    def add_task_location(self, name: str, tcp2base: np.ndarray, approach_mm: float) -> str:
        """A task location at ``tcp2base`` (4, 4) mm in base; an empty ``name`` is the next ``location_<n>``.
        Returns its name and says it in the log."""
        name = name.strip() or f"location_{len(self._cell.workcell.task_locations) + 1}"
        self._editor.add_task_location(name, tcp2base, approach_mm)
        self._log.say(f"task location {name} added")
        return name

    def snap_feature(self, component: str, point_component_mm, radius_mm: float):
        return self._editor.snap_feature(component, point_component_mm, radius_mm)

    def add_feature(self, component: str, name: str, point_component_mm) -> None:
        self._editor.add_feature(component, name, point_component_mm)

    def save(self):
        return self._editor.save()
