"""The operator core's files: the workspace (save, open bound to its cell), the corrections exported for a
controller, and the session recording. A part of :class:`~calib_core.operator.core.OperatorCore`, kept in its own
file; it uses the core's cell, session, task locations, events and recorder."""

from __future__ import annotations

from pathlib import Path

from calib_core.calibration.session import CalibrationError


class SessionFiles:
    def workspace(self):
        from calib_core.workspace.workspace import Workspace

        return Workspace(str(self.workcell.path), self.intrinsics, dict(self.workcell.task_locations), self.session.target, self.session.pairs.pairs(), self.session.corrections, cell=self.cell.identity.to_dict())

    def save_workspace(self, path) -> None:
        from calib_core.workspace.workspace import save_workspace

        save_workspace(path, self.workspace())
        self.message.emit(f"workspace saved to {path}")

    def open_workspace(self, path) -> None:
        """Load pairs, corrections and task locations. A file of another cell, or a bad one, is
        refused before anything changes."""
        from calib_core.workspace.workspace import load_workspace

        ws = load_workspace(path)  # raises before anything is changed
        self.cell.check_identity(ws.cell, f"workspace {path}")
        if ws.target and ws.target not in {c.name for c in self.workcell.components}:
            raise CalibrationError(f"workspace {path}: target {ws.target!r} is not a component of the open cell {self.cell.name!r}")
        self.workcell.task_locations.update(ws.task_locations)
        if ws.target:
            self.session.set_target(ws.target)
        self.session.pairs.replace_all(ws.pairs)
        self.session.pairs._next_number = max([p.number for p in ws.pairs], default=0) + 1
        self.session.corrections.replace_with(ws.corrections)
        self.session.undo.clear()
        self.message.emit(f"workspace {path} opened: {len(ws.pairs)} pairs, {len(ws.corrections.tasks())} corrected locations")

    def export_corrections(self, path, fmt: str) -> None:
        """Write the corrected task locations as ``fmt`` (``videocal export``'s formats) to ``path``, atomically."""
        from calib_core.atomic_file import atomic_write_text
        from calib_core.workspace.exports import export_corrections

        if not self.session.corrections.tasks():
            raise CalibrationError("no corrections stored yet: calibrate at a task location and store its correction first")
        atomic_write_text(path, export_corrections(fmt, self.session.corrections, self.workcell.task_locations, Path(path).name.split(".")[0], self.robot))
        self.message.emit(f"corrections exported to {path} ({fmt})")

    def start_recording(self, path, **options) -> None:
        """Record the session to ``path`` (MCAP); ``options`` go to the
        :class:`~calib_core.recording.recorder.SessionRecorder` (``frames="jpeg"``, ``clock``...)."""
        from calib_core.operator.recording_tap import RecordingTap
        from calib_core.recording.recorder import SessionRecorder

        self.stop_recording()
        self.recorder = SessionRecorder(path, **options)
        self._tap = RecordingTap(self, self.recorder)
        self.message.emit(f"recording to {path}")

    def recording_failure(self) -> str | None:
        """Poll the recorder (the window does on its status tick): when its disk or encoder failed, the
        recording is stopped and the reason returned, once. ``None`` while all is well."""
        rec = self.recorder
        if rec is None or rec.failure is None:
            return None
        failure = rec.failure
        self.stop_recording()
        return failure

    def stop_recording(self) -> None:
        rec = self.recorder
        if rec is not None:
            self._tap.detach()
            rec.close()
            if rec.failure is not None:
                self.message.emit(f"recording {rec.path} stopped: {rec.failure}. The file keeps what was written before; `videocal recover` completes it")
            elif not rec.finished:
                self.message.emit(f"recording {rec.path}: the file is being finished in the background")
            else:
                dropped = f", {rec.frames_dropped} frames dropped" if rec.frames_dropped else ""
                self.message.emit(f"recording {rec.path} closed ({rec.messages} messages, {rec.frames_written} frames{dropped})")
        self.recorder, self._tap = None, None
