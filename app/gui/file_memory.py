"""The window's memory of files: the recent list (a menu) and the minute-by-minute autosave.

The recent lists live in the window's ``QSettings`` (``files/recent`` and ``files/recent_cells``, newest
first). Each window autosaves to its own ``<user data>/recovery/autosave-<pid>-<start>.<window>.json``
(``files/autosave_dir`` overrides the folder), only when the session changed; a session that ended without
saving leaves its file, and the next window offers it.
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Callable
from pathlib import Path

import platformdirs
from PySide6.QtCore import QSettings, QTimer
from PySide6.QtGui import QAction
from PySide6.QtWidgets import QMenu

from calib_core.errors import VideocalError

_WINDOWS = itertools.count(1)

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
    """Every minute, the session to this window's own recovery file, when it changed since the last save.

    ``revision()`` counts the session's changes (the core's ``revision``); ``save(path)`` writes it;
    ``report(text)`` tells the operator when a write fails. The file is
    ``<recovery folder>/autosave-<pid>-<start time>.<window>.json``: two windows never share one, and a new window
    never writes over the autosave of a session that ended without saving, which :meth:`orphans` finds.
    """

    def __init__(
        self,
        settings: QSettings,
        revision: Callable[[], int],
        save: Callable[[Path], None],
        report: Callable[[str], None],
        parent,
    ):
        self.settings = settings
        self._revision = revision
        self._save = save
        self._report = report
        self.folder = Path(settings.value("files/autosave_dir") or platformdirs.user_data_dir("videocal")) / "recovery"
        # the start time and the window's number in this process: two windows opened in one second differ
        self.path = self.folder / f"autosave-{os.getpid()}-{int(time.time())}.{next(_WINDOWS)}.json"
        self._written = revision()  # the revision last written to a file (autosave or deliberate save)
        self._saved = revision()  # the revision last saved by the operator
        self.timer = QTimer(parent)
        self.timer.setInterval(AUTOSAVE_INTERVAL_MS)
        self.timer.timeout.connect(self.save_now)
        self.timer.start()

    def save_now(self) -> bool:
        """Write the session if it changed since the last write; True if a file was written."""
        revision = self._revision()
        if revision == self._written:
            return False
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._save(self.path)
        except (OSError, VideocalError) as exc:
            self._report(f"autosave failed: {exc}")
            return False
        self._written = revision
        return True

    @property
    def unsaved(self) -> bool:
        """The session changed since the operator last saved it (or since the window opened)."""
        return self._revision() != self._saved

    def mark_saved(self) -> None:
        """The operator saved the session: nothing is left to recover from this window."""
        self._saved = self._written = self._revision()
        self.path.unlink(missing_ok=True)

    def finish(self) -> None:
        """The window closes: unsaved work stays in the recovery file (offered at the next start); saved work leaves
        none."""
        self.timer.stop()
        if self._revision() == self._saved:
            self.path.unlink(missing_ok=True)
        else:
            self.save_now()

    def orphans(self) -> list[Path]:
        """Autosaves of sessions that ended without saving (their window is gone), newest first."""
        if not self.folder.is_dir():
            return []
        found = []
        for path in self.folder.glob("autosave*.json"):
            parts = path.stem.split("-")
            pid = int(parts[1]) if len(parts) == 3 and parts[1].isdigit() else None
            if path != self.path and (pid is None or not _alive(pid)):
                found.append(path)
        return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)

    def set_aside(self, path: Path) -> None:
        """A restored autosave is not offered again (kept as ``recovered-...``)."""
        path.replace(path.with_name("recovered-" + path.name))


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
