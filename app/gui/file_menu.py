"""The File menu and what it does: cells, workspaces, exports, recordings, the recent lists and the
autosave. Every action goes through the window's error boundary; one that fails changes nothing
(a failed save is not a recent file and does not count as saved)."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QTimer
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QFileDialog, QMenu

from app.gui.camera_chooser import CameraChooser
from app.gui.confirm import ask, ask_save
from app.gui.error_boundary import attempt
from app.gui.file_memory import Autosave, RecentFiles
from calib_core.errors import OperatorError

EXPORT_FILTERS = {
    "URScript, Universal Robots (*.script)": "urscript",
    "RAPID module, ABB (*.mod)": "rapid",
    "KRL data, KUKA (*.dat)": "krl",
    "TP program, FANUC (*.ls)": "fanuc",
    "PDL2, COMAU (*.pdl)": "pdl2",
    "CSV (*.csv)": "csv",
    "JSON (*.json)": "json",
}


class FileMenu:
    """Builds ``menu`` for ``window`` (a :class:`~app.gui.main_window.MainWindow`: the dialogs' parent, its settings,
    error boundary and replay) and handles it, given the core's parts it works on: the workspace ``files``, the cell
    ``editor`` (Save cell), the session's ``recording``, the calibration ``session`` (what an unsaved close would
    lose), ``revision()`` (the core's change count, for the autosave) and ``cell_folder()`` (where dialogs open)."""

    def __init__(
        self,
        window,
        menu: QMenu,
        *,
        files,
        editor,
        recording,
        session,
        revision: Callable[[], int],
        cell_folder: Callable[[], Path],
    ):
        self.window = window
        self._files, self._editor, self._recording, self._session = files, editor, recording, session
        self._revision, self._cell_folder = revision, cell_folder
        self.menu = menu
        self.autosave: Autosave | None = None
        self.restore_action: QAction | None = None
        self.workspace_path: str | None = None  # the workspace last saved or opened: Save goes there
        w = window
        self.open_cell_action = QAction(
            "Open &cell...", w, shortcut=QKeySequence("Ctrl+Shift+C"), triggered=self._open_cell_dialog
        )
        menu.addAction(self.open_cell_action)
        self.recent_cells = RecentFiles(
            w.settings, menu.addMenu("Recent ce&lls"), self.open_cell, key="files/recent_cells"
        )
        if w.launcher is None:
            self.open_cell_action.setEnabled(False)
            self.open_cell_action.setToolTip("this window was opened on one cell only")
        menu.addSeparator()
        menu.addAction(
            QAction("&Open workspace...", w, shortcut=QKeySequence.StandardKey.Open, triggered=self._open_dialog)
        )
        menu.addAction(
            QAction(
                "&Save workspace",
                w,
                shortcut=QKeySequence.StandardKey.Save,
                triggered=lambda: self.save_workspace_dialog(),
            )
        )
        menu.addAction(
            QAction("Save workspace &as...", w, shortcut=QKeySequence("Ctrl+Alt+S"), triggered=self._save_dialog)
        )
        menu.addAction(
            QAction(
                "Save ce&ll",
                w,
                shortcut=QKeySequence("Ctrl+Shift+S"),
                triggered=lambda: w.report(self._editor.save)(),
            )
        )
        menu.addAction(
            QAction("E&xport corrections...", w, shortcut=QKeySequence("Ctrl+E"), triggered=self._export_dialog)
        )
        menu.addSeparator()
        self.record_action = QAction("&Record session...", w, checkable=True, triggered=self._record_toggled)
        menu.addAction(self.record_action)
        menu.addAction(
            QAction(
                "Open r&ecording...", w, shortcut=QKeySequence("Ctrl+Shift+O"), triggered=self._open_recording_dialog
            )
        )
        self.recent = RecentFiles(w.settings, menu.addMenu("Recent &files"), self.open_recent)
        menu.addSeparator()
        self.camera = CameraChooser(w, menu)
        self.recorder_watch = QTimer(w, interval=250, timeout=self.watch_recorder)
        menu.addSeparator()
        # StandardKey.Quit is empty on some platforms (the offscreen one among them).
        menu.addAction(QAction("&Quit", w, shortcut=QKeySequence("Ctrl+Q"), triggered=w.close))

    def _status(self, text: str, ms: int = 8000) -> None:
        self.window.statusBar().showMessage(text, ms)

    # --- cells ---------------------------------------------------------------------------------------
    def open_cell(self, path: str) -> bool:
        """Open another cell: a new window on it (with its own simulator or the same real devices) takes
        this one's place. A cell that does not load leaves this window as it is."""
        w = self.window
        if w.launcher is None:
            w.show_error("this window was opened on one cell only: start videocal gui --workcell FILE")
            return False
        from calib_core.operator.cell import Cell

        if not attempt(w.show_error, Cell.open, path):  # check the file before anything stops
            return False
        opened = []
        if not attempt(w.show_error, lambda: opened.append(w.launcher.open(path))):
            return False
        opened[0].setGeometry(w.geometry())
        opened[0].show()
        w.close()
        return True

    def _open_cell_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self.window,
            "Open cell",
            str(self._cell_folder()),
            "videocal workcell (*.yaml *.yml)",
        )
        if path:
            self.open_cell(path)

    # --- workspaces and exports ---------------------------------------------------------------------
    def save_workspace(self, path) -> bool:
        """Save; only a save that succeeded joins the recent files and counts as saved for the autosave.
        The recovery folder holds autosaves only: a save there is refused."""
        if Path(path).resolve().parent == self.autosave.folder.resolve():
            self.window.show_error(
                f"{path}: that is the recovery folder, which holds autosaves only; save the workspace somewhere else"
            )
            return False
        if not attempt(self.window.show_error, self._files.save_workspace, path):
            return False
        self.recent.remember(path)
        self.autosave.mark_saved()
        self.workspace_path = str(path)
        return True

    def open_workspace(self, path, *, restored: bool = False) -> bool:
        """Open a workspace file. ``restored``: an autosave, which is no file of the operator's: it joins
        no recent list and *Save* asks where (it once wrote into the recovery folder, offered again at
        the next start as an unsaved autosave)."""
        if not attempt(self.window.show_error, lambda: self._files.open_workspace(path, hold=not restored)):
            return False
        if restored:
            self.workspace_path = None
            return True
        self.recent.remember(path)
        self.workspace_path = str(path)
        return True

    def open_recent(self, path: str) -> None:
        """A workspace (.json) or a recording (.mcap) from the recent list."""
        if path.endswith(".mcap"):
            self.open_recording(path)
        else:
            self.open_workspace(path)

    def _save_dialog(self) -> None:
        self.save_workspace_dialog(ask_path=True)

    def save_workspace_dialog(self, ask_path: bool = False) -> bool:
        """Save to the workspace last saved or opened (or ask where); True when it was saved."""
        path = None if ask_path else self.workspace_path
        if path is None:
            path, _ = QFileDialog.getSaveFileName(
                self.window, "Save workspace", "workspace.json", "videocal workspace (*.json)"
            )
        return bool(path) and self.save_workspace(path)

    def _open_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "Open workspace", "", "videocal workspace (*.json)")
        if path:
            self.open_workspace(path)

    def _export_dialog(self) -> None:
        path, chosen = QFileDialog.getSaveFileName(
            self.window, "Export corrections", "corrections.script", ";;".join(EXPORT_FILTERS)
        )
        if path:
            self.window.report(self._files.export_corrections)(path, EXPORT_FILTERS.get(chosen, "csv"))

    # --- recordings -----------------------------------------------------------------------------------
    def _open_recording_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "Open recording", "", "MCAP recording (*.mcap)")
        if path:
            self.open_recording(path)

    def open_recording(self, path) -> None:
        """Replay a recording: the live camera pauses, the views follow the recording (see ReplayBar)."""
        self.window.report(self._open_recording)(path)

    def _open_recording(self, path) -> None:
        w = self.window
        if self._recording.recorder is not None:
            raise OperatorError("stop recording before replaying a recording")
        w.replay.open(path)
        w.commands.live.setChecked(False)
        self.recent.remember(path)

    def start_recording(self, path, **options) -> None:
        w = self.window
        if w.replay.playback is not None:
            w.show_error("close the replay before recording: a recording records the live camera and robot")
            return
        w.report(self._recording.start)(path, **options)
        self.record_action.setChecked(self._recording.recorder is not None)
        if self._recording.recorder is not None:
            self.recorder_watch.start()

    def stop_recording(self) -> None:
        self.recorder_watch.stop()
        self._recording.stop()
        self.record_action.setChecked(False)

    def watch_recorder(self) -> None:
        """A recorder whose disk or encoder failed has stopped: REC goes off, the operator learns why and
        may record on, as JPEG frames (no video encoder) into a new file."""
        w = self.window
        rec = self._recording.recorder
        failure = self._recording.failure()
        if failure is None:
            return
        self.recorder_watch.stop()
        self.record_action.setChecked(False)
        w.show_error(f"recording {rec.path.name} stopped: {failure}")
        again = rec.path.with_name(f"{rec.path.stem}-jpeg{rec.path.suffix}")
        text = (
            f"Recording to {rec.path} stopped: {failure}.\n\nThe file keeps what was written before the failure "
            f"(videocal recover completes it). Record on to {again.name}, with JPEG frames instead of H.264 video?"
        )
        if ask(w, "Recording stopped", text, "Record as JPEG"):
            self.start_recording(again, frames="jpeg")

    def _record_toggled(self, on: bool) -> None:
        if not on:
            self.stop_recording()
            return
        path, _ = QFileDialog.getSaveFileName(self.window, "Record session", "session.mcap", "MCAP recording (*.mcap)")
        if path:
            self.start_recording(path)
        else:
            self.record_action.setChecked(False)

    # --- the autosave ---------------------------------------------------------------------------------
    def start_autosave(self) -> None:
        """Autosave every minute when the session changed. Sessions that ended without saving left their
        autosave: offer each (File > Restore autosave of ...) rather than load one unasked."""
        self.autosave = Autosave(
            self.window.settings,
            self._revision,
            lambda path: self._files.save_workspace(path, hold=False),
            self._status,
            self.window,
        )
        self.restore_actions: dict[str, QAction] = {}
        for path in self.autosave.orphans():
            stamp = time.strftime("%Y-%m-%d %H:%M", time.localtime(path.stat().st_mtime))
            action = QAction(
                f"Restore &autosave of {stamp}",
                self.window,
                triggered=lambda checked=False, p=path: self.restore_autosave(p),
            )
            self.menu.insertAction(self.menu.actions()[0], action)
            self.restore_actions[str(path)] = action
        self.restore_action = next(iter(self.restore_actions.values()), None)
        if self.restore_actions:
            self._status(
                f"{len(self.restore_actions)} unsaved session(s) were autosaved: File > Restore autosave", 30000
            )

    def restore_autosave(self, path=None) -> bool:
        """Open an autosave (the newest by default); once restored it is not offered again."""
        if path is None:
            if not self.restore_actions:
                return False
            path = next(iter(self.restore_actions))
        path = Path(path)
        if not self.open_workspace(path, restored=True):
            return False
        self.autosave.set_aside(path)
        action = self.restore_actions.pop(str(path), None)
        if action is not None:
            self.menu.removeAction(action)
        self.restore_action = next(iter(self.restore_actions.values()), None)
        return True

    def may_close(self) -> bool:
        """Unsaved work: ask to save it, discard it (it stays in the recovery file) or stay. A quit by a
        signal (SIGTERM, Ctrl+C in the terminal) or with ``window/ask_unsaved`` off asks nothing."""
        from PySide6.QtWidgets import QApplication

        w = self.window
        if (
            self.autosave is None
            or not self.autosave.unsaved
            or QApplication.instance().property("videocal_quit_by_signal")
        ):
            return True
        if str(w.settings.value("window/ask_unsaved", "true")).lower() in ("false", "0"):
            return True
        s = self._session
        what = (
            f"{len(s.pairs)} pairs, {sum(len(s.corrections.history(t)) for t in s.corrections.tasks())} stored "
            "corrections"
        )
        choice = ask_save(
            w,
            "Unsaved work",
            f"The session has changes that are not saved in a workspace file ({what}). Save them before closing?\n"
            "Discard closes the window; the changes stay in the recovery file, offered at the next start.",
        )
        if choice == "cancel":
            return False
        if choice == "save":
            return self.save_workspace_dialog()
        return True
