"""The window's memory of files: the recent list (a menu) and the minute-by-minute autosave.

Both live in the window's ``QSettings``: ``files/recent`` and ``files/recent_cells`` (newest first) and ``files/last_saved_time``
(Unix s of the last deliberate save). The autosave goes to ``<user data>/recovery/autosave.json``
(``files/autosave_dir`` overrides the folder) and is offered again when it is newer than that save.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import platformdirs
from PySide6.QtCore import QSettings, QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMenu

RECENT_MAX = 8
AUTOSAVE_INTERVAL_MS = 60_000


class RecentFiles:
    """Workspaces and recordings opened or saved, newest first, as a menu whose entries call ``open_path``."""

    def __init__(self, settings: QSettings, menu: QMenu, open_path: Callable[[str], None], key: str = "files/recent"):
        self.settings = settings
        self.menu = menu
        self.key = key
        self._open_path = open_path
        menu.aboutToShow.connect(self.fill)

    def paths(self) -> list[str]:
        value = self.settings.value(self.key) or []
        return [p for p in ([value] if isinstance(value, str) else value) if p]

    def remember(self, path) -> None:
        recent = [str(path)] + [p for p in self.paths() if p != str(path)]
        self.settings.setValue(self.key, recent[:RECENT_MAX])

    def fill(self) -> None:
        self.menu.clear()
        paths = self.paths()
        if not paths:
            self.menu.addAction(QAction("(none yet)", self.menu, enabled=False))
        for path in paths:
            self.menu.addAction(QAction(path, self.menu, triggered=lambda checked=False, p=path: self._open_path(p)))


class Autosave:
    """Every minute, ``save(path)`` of the session to the recovery file; ``report(text)`` when it fails."""

    def __init__(self, settings: QSettings, save: Callable[[Path], None], report: Callable[[str], None], parent):
        self.settings = settings
        self._save = save
        self._report = report
        self.path = Path(settings.value("files/autosave_dir") or platformdirs.user_data_dir("videocal")) / "recovery" / "autosave.json"
        self.timer = QTimer(parent)
        self.timer.setInterval(AUTOSAVE_INTERVAL_MS)
        self.timer.timeout.connect(self.save_now)
        self.timer.start()

    def save_now(self) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._save(self.path)
        except OSError as exc:
            self._report(f"autosave failed: {exc}")

    def mark_saved(self) -> None:
        """The operator saved the session: the autosave is no longer newer than the saved file."""
        self.settings.setValue("files/last_saved_time", time.time())

    def unsaved_since(self) -> float | None:
        """The autosave's time (Unix s) when it is newer than the last deliberate save, else ``None``:
        the last session then ended without saving."""
        if not self.path.is_file():
            return None
        autosaved = self.path.stat().st_mtime
        last_saved = self.settings.value("files/last_saved_time")
        return None if last_saved is not None and float(last_saved) >= autosaved else autosaved
