"""The command panel's model: the task locations and the one chosen, the target, the solve options, the stored
corrections."""

from __future__ import annotations

from calib_core.calibration.commands import ClearPairs
from calib_core.calibration.session import CalibrationSession
from calib_core.calibration.solve_options import SetOption
from calib_core.operator.cell import Cell
from calib_core.operator.cell_editor import CellEditor
from calib_core.operator.task_choice import TaskChoice


class CommandsPaneModel:
    """What the command panel shows and sets: the cell's task locations and the one worked at (its approach
    distance), the components a calibration can target and the target, the solve options, the corrections stored.
    Every setting is an undoable command or the task choice; the actions that move the robot or open dialogs are the
    window's.

    Its public members: four events (``task_changed(name)``, ``scene_changed()``, ``options_changed(name, value)``,
    ``corrections_changed(task)``), six values shown (``task``, ``task_names``, ``target``, ``target_names``,
    ``options``, ``corrections``) and five settings."""

    def __init__(self, cell: Cell, session: CalibrationSession, tasks: TaskChoice, editor: CellEditor):
        self._cell, self._session, self._tasks, self._editor = cell, session, tasks, editor
        self.task_changed = tasks.changed
        self.scene_changed = cell.scene_changed
        self.options_changed = session.options.changed
        self.corrections_changed = session.corrections.changed
        self.options = session.options
        self.corrections = session.corrections

    @property
    def task(self):
        """The task location worked at (a TaskLocation), or ``None``."""
        return self._tasks.task

    @property
    def task_names(self) -> list[str]:
        return list(self._cell.workcell.task_locations)

    @property
    def target(self) -> str | None:
        return self._session.target

    @property
    def target_names(self) -> list[str]:
        """The cell's components a calibration can target (not the floor, walls or the robot's mount)."""
        return [c.name for c in self._cell.workcell.components if c.kind == "component"]

    def choose_task(self, name: str) -> None:
        self._tasks.choose(name)

    def set_task_approach(self, mm: float) -> None:
        """The chosen task location's approach distance, mm (undoable); nothing while none is chosen."""
        if self._tasks.task is not None:
            self._editor.set_task_approach(self._tasks.task.name, mm)

    def set_target(self, name: str) -> None:
        self._session.set_target(name)

    def set_option(self, name: str, value: bool) -> None:
        """A solve option (``estimate_focal``, ``robust``), undoable."""
        self._session.undo.push(SetOption(self._session.options, name, value))

    def clear_pairs(self) -> None:
        """Every pair removed, undoable."""
        self._session.undo.push(ClearPairs(self._session.pairs))
