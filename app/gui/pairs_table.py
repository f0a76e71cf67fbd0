"""The correspondence table: number, feature, 3D point (mm), 2D point (px), residual (px), enabled."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableWidget, QTableWidgetItem

from calib_core.operator.panes.pairs import PairsTableModel

COLUMNS = ("#", "feature", "X mm", "Y mm", "Z mm", "u px", "v px", "residual px", "use")


class PairsTable(QTableWidget):
    def __init__(self, model: PairsTableModel, parent=None):
        super().__init__(0, len(COLUMNS), parent)
        self.pairs_model = model
        self.setHorizontalHeaderLabels(COLUMNS)
        self.verticalHeader().setVisible(False)
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.horizontalHeader().setStretchLastSection(True)
        self._updating = False
        self.itemChanged.connect(self._on_item_changed)
        model.pairs_changed.connect(lambda *_: self.refresh())
        model.result_changed.connect(self.refresh)

    def selected_number(self) -> int | None:
        rows = self.selectionModel().selectedRows()
        if not rows:
            return None
        item = self.item(rows[0].row(), 0)
        return int(item.text()) if item is not None else None

    def select_number(self, number: int) -> None:
        """Select the row of pair ``number`` (a click on its point in a pane)."""
        for row in range(self.rowCount()):
            item = self.item(row, 0)
            if item is not None and item.text() == str(number):
                self.selectRow(row)
                return

    def _residuals(self) -> dict[int, float]:
        result = self.pairs_model.result.estimate
        if result is None:
            return {}
        numbers = self.pairs_model.result.solved_numbers
        norms = result.solution.residual_norms_px
        return {n: float(r) for n, r in zip(numbers, norms)}

    def _suspects(self) -> set[int]:
        """The pairs the last solve rejected or found not to fit the others (drawn red, with why)."""
        result = self.pairs_model.result.estimate
        if result is None:
            return set()
        s = result.solution
        flags = np.asarray(s.outliers, dtype=bool) | (
            np.asarray(s.misfits, dtype=bool) if s.misfits is not None else False
        )
        return {n for n, f in zip(self.pairs_model.result.solved_numbers, flags) if f}

    def refresh(self) -> None:
        self._updating = True
        pairs = self.pairs_model.pairs.pairs()
        residuals = self._residuals()
        suspects = self._suspects()
        self.setRowCount(len(pairs))
        for row, p in enumerate(pairs):
            x, y, z = p.point_world_mm
            u, v = p.pixel if p.pixel is not None else (np.nan, np.nan)
            texts = [
                str(p.number),
                p.feature or "(surface)",
                f"{x:.1f}",
                f"{y:.1f}",
                f"{z:.1f}",
                "pending" if p.pixel is None else f"{u:.2f}",
                "" if p.pixel is None else f"{v:.2f}",
                f"{residuals[p.number]:.2f}" if p.number in residuals else "",
            ]
            for col, text in enumerate(texts):
                item = QTableWidgetItem(text)
                item.setTextAlignment(
                    Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter
                    if col >= 2
                    else Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter
                )
                if p.number in suspects and col in (0, 7):
                    item.setForeground(QColor(230, 80, 70))
                    item.setToolTip("this pick does not fit the others (the last solve): check it, or untick it")
                self.setItem(row, col, item)
            check = QTableWidgetItem()
            check.setFlags(Qt.ItemFlag.ItemIsUserCheckable | Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable)
            check.setCheckState(Qt.CheckState.Checked if p.enabled else Qt.CheckState.Unchecked)
            self.setItem(row, len(COLUMNS) - 1, check)
        self._updating = False

    def _on_item_changed(self, item: QTableWidgetItem) -> None:
        if self._updating or item.column() != len(COLUMNS) - 1:
            return
        number = int(self.item(item.row(), 0).text())
        enabled = item.checkState() == Qt.CheckState.Checked
        self.pairs_model.set_enabled(number, enabled)
