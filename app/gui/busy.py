"""The busy indicator for work that holds the window for more than a moment: a wait cursor and a
status line, taken down however the work ends."""

from __future__ import annotations

from contextlib import contextmanager

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication, QWidget


@contextmanager
def busy(widget: QWidget, text: str = ""):
    """Show the wait cursor (and ``text`` in the window's status bar) while the block runs; the line is cleared after
    it unless the work put a message of its own there."""
    window = widget.window()
    bar = window.statusBar() if hasattr(window, "statusBar") else None
    if bar is not None and text:
        bar.showMessage(text)
    QApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
    QApplication.processEvents()  # the cursor and the line show before the work starts
    try:
        yield
    finally:
        QApplication.restoreOverrideCursor()
        if bar is not None and text and bar.currentMessage() == text:
            bar.clearMessage()  # the work is over: the line no longer says it is under way
