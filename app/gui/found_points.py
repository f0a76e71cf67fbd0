"""*Find points* in the window (F6): the core finds the target's features on the held frame; a list
shows each proposal (feature, kind, confidence, distance from the fitted pose, and why a detector was unsure) with a
check box and
each feature not found with the reason; *Accept checked* adds the checked ones as pairs, one undo
step. The camera pane draws the proposals (it hears ``points_found``) while the list is open."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QLabel,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

from app.gui.busy import busy
from app.gui.error_boundary import attempt


class FoundPointsDialog(QDialog):
    """The proposals of one Find points, to accept all or some."""

    def __init__(self, found, accept, calibrate_on_edges=None, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Points found")
        self.found = found
        self._accept_features = accept
        self._on_edges = calibrate_on_edges
        result = found.result
        layout = QVBoxLayout(self)
        self.message = QLabel(result.message)
        self.message.setTextFormat(Qt.TextFormat.PlainText)
        self.message.setWordWrap(True)
        layout.addWidget(self.message)
        self.table = QTableWidget(len(result.proposals), 5, self)
        self.table.setHorizontalHeaderLabels(["feature", "kind", "confidence", "off the fit (px)", "unsure because"])
        for row, p in enumerate(result.proposals):
            name = QTableWidgetItem(p.feature)
            name.setFlags(Qt.ItemFlag.ItemIsUserCheckable | Qt.ItemFlag.ItemIsEnabled)
            name.setCheckState(Qt.CheckState.Checked)
            self.table.setItem(row, 0, name)
            for col, text in ((1, p.kind), (2, f"{p.confidence:.2f}"), (3, f"{p.residual_px:.2f}"), (4, p.why)):
                item = QTableWidgetItem(text)
                item.setFlags(Qt.ItemFlag.ItemIsEnabled)
                self.table.setItem(row, col, item)
        self.table.resizeColumnsToContents()
        self.table.horizontalHeader().setStretchLastSection(True)
        layout.addWidget(self.table)
        self.missed = QLabel("\n".join(f"{m.feature}: {m.reason}" for m in result.missed) or "every feature was found")
        self.missed.setTextFormat(Qt.TextFormat.PlainText)
        self.missed.setWordWrap(True)
        layout.addWidget(self.missed)
        buttons = QDialogButtonBox(self)
        self.accept_button = QPushButton("Accept checked")
        self.accept_button.setDefault(True)
        self.accept_button.setEnabled(bool(result.proposals))
        buttons.addButton(self.accept_button, QDialogButtonBox.ButtonRole.AcceptRole)
        self.edges_button = QPushButton("Calibrate on edges")
        self.edges_button.setToolTip(
            "Solve from the target's edges on this frame (hundreds of samples, no pairs): usually the most accurate"
        )
        edges = result.edges
        self.edges_button.setEnabled(edges is not None and edges.settled)
        buttons.addButton(self.edges_button, QDialogButtonBox.ButtonRole.ActionRole)
        self.edges_button.clicked.connect(self._calibrate_on_edges)
        buttons.addButton(QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self._accept_checked)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(520, 420)

    def checked_features(self) -> list[str]:
        return [
            self.table.item(r, 0).text()
            for r in range(self.table.rowCount())
            if self.table.item(r, 0).checkState() == Qt.CheckState.Checked
        ]

    def _calibrate_on_edges(self) -> None:
        if self._on_edges is not None and self._on_edges():
            self.accept()

    def _accept_checked(self) -> None:
        if self._accept_features(self.checked_features()):
            self.accept()


class FindPoints:
    """The F6 action of a main window: Find points by ``finder`` (the core's, see
    :class:`~calib_core.operator.point_finding.PointFinding`), its proposals in a dialog over ``parent``; errors to
    ``show_error(text)``, news to ``show_message(text, ms)``. The window puts :attr:`action` in its menu and wires its
    Find points button to :meth:`run`."""

    def __init__(self, finder, parent, show_error, show_message):
        self.finder, self.parent = finder, parent
        self.show_error, self.show_message = show_error, show_message
        self.dialog: FoundPointsDialog | None = None
        self.action = QAction("&Find points", parent, shortcut=QKeySequence("F6"), triggered=self.run)
        self.action.setToolTip("Find the target's features on the camera image and propose them as pairs (F6)")

    def run(self) -> None:
        found = {}
        with busy(self.parent, "finding points ..."):  # rendering and fitting take a second
            if not attempt(self.show_error, lambda: found.setdefault("found", self.finder.find_points())):
                return
        self.show(found["found"])

    def show(self, found) -> None:
        if self.dialog is not None:
            self.dialog.close()
        self.dialog = FoundPointsDialog(found, self._accept, self._calibrate_on_edges, self.parent)
        self.dialog.finished.connect(lambda _: self.finder.dismiss_found_points())  # the camera pane hides them
        self.dialog.show()

    def _calibrate_on_edges(self) -> bool:
        return attempt(self.show_error, self.finder.calibrate_on_edges)

    def _accept(self, features: list[str]) -> bool:
        if not features:
            self.show_error("check at least one point to accept, or Cancel")
            return False
        numbers = {}
        ok = attempt(self.show_error, lambda: numbers.setdefault("n", self.finder.accept_found_points(features)))
        if ok:
            self.show_message(f"pairs {', '.join(map(str, numbers['n']))} added from the points found", 8000)
        return ok
