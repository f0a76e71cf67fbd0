"""Which task location the operator works at: the one the moves go to, the corrections are stored for
and the verdict's tolerance comes from. ``changed(name)`` after a choice, or after the named task
location was edited (``task`` follows the edit; ``None`` when the chosen one was removed)."""

from __future__ import annotations

from psygnal import Signal

from calib_core.workcell import TaskLocation, Workcell


class TaskChoice:
    changed = Signal(str)

    def __init__(self, workcell: Workcell):
        self._workcell = workcell
        self.task: TaskLocation | None = next(iter(workcell.task_locations.values()), None)

    def choose(self, name: str) -> None:
        """Work at task location ``name`` (an unknown name raises, naming the known ones)."""
        self.task = self._workcell.task(name)
        self.changed.emit(name)

    def edited(self, name: str) -> None:
        """Task location ``name`` was edited, added or removed."""
        if self.task is not None and self.task.name == name:
            self.task = self._workcell.task_locations.get(name)
        self.changed.emit(name)
