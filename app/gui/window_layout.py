"""The main window's layout: its panes arranged, and kept between runs (its geometry, docks and the three splitters,
in the window's ``QSettings``: ``window/geometry``, ``window/state``, ``window/split_*``)."""

from __future__ import annotations

from PySide6.QtCore import QSettings, Qt
from PySide6.QtWidgets import QDockWidget, QLabel, QSplitter, QVBoxLayout, QWidget


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


def arrange_panes(window) -> None:
    """The panes of ``window`` in their places: the camera and the virtual camera side by side over the overview and
    the pairs with the results, the replay bar above them, the command panel docked on the left. Sets the window's
    three splitters (``splitter``, ``top_splitter``, ``bottom_splitter``) that :func:`restore_layout` puts back."""
    top = QSplitter(Qt.Orientation.Horizontal)
    top.addWidget(window.camera)
    top.addWidget(window.virtual)
    top.setSizes([700, 620])
    right_bottom = QWidget()
    rb = QVBoxLayout(right_bottom)
    rb.setContentsMargins(0, 0, 0, 0)
    rb.addWidget(QLabel("<b>Point pairs</b>"))
    rb.addWidget(window.table, 1)
    rb.addWidget(QLabel("<b>Results</b>"))
    rb.addWidget(window.results, 1)
    bottom = QSplitter(Qt.Orientation.Horizontal)
    bottom.addWidget(window.overview)
    bottom.addWidget(right_bottom)
    bottom.setSizes([700, 620])
    window.top_splitter, window.bottom_splitter = top, bottom
    window.splitter = QSplitter(Qt.Orientation.Vertical)
    window.splitter.addWidget(top)
    window.splitter.addWidget(bottom)
    window.splitter.setStretchFactor(0, 3)
    window.splitter.setStretchFactor(1, 2)
    central = QWidget()
    column = QVBoxLayout(central)
    column.setContentsMargins(0, 0, 0, 0)
    column.setSpacing(0)
    column.addWidget(window.replay)
    column.addWidget(window.splitter, 1)
    window.setCentralWidget(central)
    dock = QDockWidget("Commands", window)
    dock.setObjectName("commands_dock")
    dock.setWidget(window.commands)
    dock.setFeatures(QDockWidget.DockWidgetFeature.DockWidgetMovable)
    window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, dock)
    window.resize(1600, 1000)
