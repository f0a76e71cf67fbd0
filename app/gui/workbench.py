"""The operator core as the window uses it: the same :class:`OperatorCore`, with the link's
callbacks (on its reader thread) queued into the Qt event loop. The window only marshals threads
and draws; the state and the workflow live in :mod:`calib_core.operator`."""

from __future__ import annotations

from PySide6.QtCore import QObject, Signal

from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore
from calib_core.operator.site import Site


class _GuiThread(QObject):
    """Runs posted calls on the thread this object lives in (the GUI thread)."""

    posted = Signal(object)

    def __init__(self):
        super().__init__()
        self.posted.connect(self._run)  # emitted from another thread: queued

    def _run(self, call) -> None:
        fn, args = call
        fn(*args)

    def call_soon(self, fn, *args) -> None:
        self.posted.emit((fn, args))


class Workbench(OperatorCore):
    """:class:`OperatorCore` whose events all happen on the GUI thread."""

    def __init__(self, cell: Cell, site: Site | None = None):
        self._gui_thread = _GuiThread()
        super().__init__(cell, site, call_soon=self._gui_thread.call_soon)
