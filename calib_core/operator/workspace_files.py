"""The operator core's files: the workspace (save, open bound to its cell) and the corrections exported for a
controller. A part of :class:`~calib_core.operator.core.OperatorCore` (``core.files``), given the cell, the
session and the log. (The session recording is the core's: its tap listens to every part.)"""

from __future__ import annotations

from pathlib import Path

from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.operator.cell import Cell
from calib_core.operator.operator_log import OperatorLog


class WorkspaceFiles:
    def __init__(self, cell: Cell, session: CalibrationSession, log: OperatorLog):
        self.cell, self.session, self.log = cell, session, log
        self._lock = None  # the workspace file this window holds (one window at a time on a file)

    def _hold(self, path) -> None:
        """Hold ``path``'s lock (:class:`~calib_core.workspace.workspace_lock.WorkspaceInUse` when another window
        has it), releasing the one held before."""
        from calib_core.workspace.workspace_lock import WorkspaceLock

        if self._lock is not None and self._lock.workspace == Path(path).resolve():
            return
        lock = WorkspaceLock(path)
        if self._lock is not None:
            self._lock.release()
        self._lock = lock

    def release(self) -> None:
        """Let go of the workspace file (the window closes)."""
        if self._lock is not None:
            self._lock.release()
            self._lock = None

    def workspace(self):
        from calib_core.workspace.workspace import Workspace

        return Workspace(
            str(self.cell.workcell.path),
            self.cell.intrinsics,
            dict(self.cell.workcell.task_locations),
            self.session.target,
            self.session.pairs.pairs(),
            self.session.corrections,
            cell=self.cell.identity.to_dict(),
        )

    def save_workspace(self, path, *, hold: bool = True) -> None:
        """Write the workspace to ``path``, holding it for this window (``hold``; an autosave into the recovery
        folder, a file of this window alone, holds nothing)."""
        from calib_core.workspace.workspace import save_workspace

        if hold:
            self._hold(path)
        save_workspace(path, self.workspace())
        self.log.say(f"workspace saved to {path}")

    def open_workspace(self, path, *, hold: bool = True) -> None:
        """Load pairs, corrections and task locations. A file of another cell, or a bad one, or one another window
        holds, is refused before anything changes. ``hold``: hold the file for this window (an autosave being
        restored is not the operator's file: it is not held)."""
        from calib_core.workspace.workspace import load_workspace

        ws = load_workspace(path)  # raises before anything is changed
        self.cell.check_identity(ws.cell, f"workspace {path}")
        if hold:
            self._hold(path)
        if ws.target and ws.target not in {c.name for c in self.cell.workcell.components}:
            raise CalibrationError(
                f"workspace {path}: target {ws.target!r} is not a component of the open cell {self.cell.name!r}"
            )
        self.cell.workcell.task_locations.update(ws.task_locations)
        if ws.target:
            self.session.set_target(ws.target)
        self.session.pairs.open(ws.pairs)
        self.session.corrections.replace_with(ws.corrections)
        self.session.undo.clear()
        self.log.say(
            f"workspace {path} opened: {len(ws.pairs)} pairs, {len(ws.corrections.tasks())} corrected locations"
        )

    def export_corrections(self, path, fmt: str) -> None:
        """Write the corrected task locations as ``fmt`` (``videocal export``'s formats) to ``path``, atomically."""
        from calib_core.atomic_file import atomic_write_text
        from calib_core.workspace.exports import export_corrections

        from calib_core.workspace.controller_formats import left_out

        if not self.session.corrections.corrected_tasks():
            raise CalibrationError(
                "no corrections stored yet: calibrate at a task location and store its correction first"
                + ("; " + "; ".join(left_out(self.session.corrections)) if self.session.corrections.tasks() else "")
            )
        atomic_write_text(
            path,
            export_corrections(
                fmt,
                self.session.corrections,
                self.cell.workcell.task_locations,
                Path(path).name.split(".")[0],
                self.cell.robot,
                self.cell.joint_map,
            ),
        )
        self.log.say(
            f"corrections exported to {path} ({fmt})"
            + "".join(f"; {line}" for line in left_out(self.session.corrections))
        )
