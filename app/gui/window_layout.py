"""The main window's layout kept between runs: its geometry, docks and the three splitters, in the
window's ``QSettings`` (``window/geometry``, ``window/state``, ``window/split_*``)."""

from __future__ import annotations

from PySide6.QtCore import QSettings


def _splitters(window) -> tuple:
    return (
        ("window/split_main", window.splitter),
        ("window/split_top", window.top_splitter),
        ("window/split_bottom", window.bottom_splitter),
    )


def restore_layout(window, settings: QSettings) -> None:
    """Put ``window`` back as it was left (nothing changes where nothing was saved)."""
    geometry = settings.value("window/geometry")
    if geometry is not None:
        window.restoreGeometry(geometry)
    state = settings.value("window/state")
    if state is not None:
        window.restoreState(state)
    for key, splitter in _splitters(window):
        value = settings.value(key)
        if value is not None:
            splitter.restoreState(value)


def save_layout(window, settings: QSettings) -> None:
    settings.setValue("window/geometry", window.saveGeometry())
    settings.setValue("window/state", window.saveState())
    for key, splitter in _splitters(window):
        settings.setValue(key, splitter.saveState())
