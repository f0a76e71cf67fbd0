"""Results of the last solve: status in words, camera pose, the end-effector displacement with
1-sigma, RMS, a per-point residual chart, and the candidates when the solve is ambiguous."""

from __future__ import annotations

import functools
import html

import numpy as np
from PySide6.QtCore import QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from calib_core.operator.panes.results import ResultsPaneModel
from calib_core.calibration.verdict import Verdict
from calib_core.calibration.view_stamp import SAME_STATE_DEG
from calib_core.solver import SolveStatus

_VERDICT_COLORS = {
    Verdict.OK: "#5fd35f",
    Verdict.AMBIGUOUS: "#ffb347",
    Verdict.UNCERTAIN: "#ffb347",
    Verdict.IMPLAUSIBLE: "#ff8c42",
    Verdict.FAILED: "#ff6b6b",
}


class ResidualChart(QWidget):
    """Bars of the per-point residual lengths (px), with the leave-one-out value as a tick."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setMinimumHeight(70)
        self.values: list[tuple[str, float, float]] = []

    def set_values(self, values: list[tuple[str, float, float]]) -> None:
        self.values = values
        self.update()

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), QColor(30, 31, 35))
        if not self.values:
            p.setPen(QColor(140, 140, 140))
            p.drawText(self.rect(), Qt.AlignmentFlag.AlignCenter, "residuals per point appear after Calibrate")
            return
        top = max(max(max(r, l if np.isfinite(l) else 0) for _, r, l in self.values), 0.5)
        n = len(self.values)
        w = self.width() / n
        h = self.height() - 16
        for i, (label, r, loo) in enumerate(self.values):
            bar = h * r / top
            p.fillRect(QRectF(i * w + 3, h - bar, w - 6, bar), QColor(255, 200, 40))
            if np.isfinite(loo):
                y = h - h * loo / top
                p.setPen(QColor(255, 80, 80))
                p.drawLine(int(i * w + 2), int(y), int((i + 1) * w - 2), int(y))
            p.setPen(QColor(200, 200, 200))
            p.drawText(QRectF(i * w, h, w, 16), Qt.AlignmentFlag.AlignCenter, label)
        p.setPen(QColor(160, 160, 160))
        p.drawText(
            QRectF(4, 2, self.width() - 8, 14), Qt.AlignmentFlag.AlignRight, f"max {top:.2f} px  (red: if left out)"
        )


class ResultsPanel(QWidget):
    """``candidate_chosen(index)`` when the operator picks one of several equally good solutions."""

    candidate_chosen = Signal(int)

    def __init__(self, model: ResultsPaneModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.verdict = QLabel("No solve yet.")
        self.verdict.setObjectName("verdict")
        self.verdict.setWordWrap(True)
        self.verdict.setTextFormat(Qt.TextFormat.RichText)
        self.status = QLabel("")
        """The last message (a refused click, a failed step): never replaces the verdict."""
        self.status.setObjectName("message")
        self.status.setWordWrap(True)
        self.status.setTextFormat(Qt.TextFormat.RichText)
        self.details = QLabel("")
        self.details.setTextFormat(Qt.TextFormat.RichText)
        self.details.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.chart = ResidualChart()
        self.candidates = QHBoxLayout()
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(self.verdict)
        layout.addWidget(self.status)
        layout.addWidget(self.details)
        layout.addLayout(self.candidates)
        layout.addWidget(self.chart, 1)
        model.result_changed.connect(self.refresh)
        model.pairs_changed.connect(lambda *_: self.refresh())  # a result whose pairs changed is marked
        self._elsewhere = False
        self._shown = None  # the estimate shown: a new one clears the message line
        model.joints_changed.connect(self._joints_changed)
        model.corrections_changed.connect(lambda *_: self.clear_message())

    def _solved_elsewhere(self) -> bool:
        """The last result was solved from another robot pose than the robot's now."""
        context = self.model.result.context
        if context is None or context.joints_deg is None or self.model.result.estimate is None:
            return False
        now = np.asarray(self.model.joints_deg, float)
        return context.joints_deg.shape != now.shape or float(np.max(np.abs(context.joints_deg - now))) > SAME_STATE_DEG

    def _joints_changed(self, _q) -> None:
        if self._solved_elsewhere() != self._elsewhere:
            self.refresh()

    def _fit_text(self) -> None:
        # A word-wrapped label in a layout under a splitter gets one line's height: the rest of a failure's
        # reason (which pair to check) was hidden under the numbers. Each text label takes the height its text
        # needs at its width; the chart gives up the room.
        for label in (self.verdict, self.status):
            label.setMinimumHeight(label.heightForWidth(max(label.width(), 100)) if label.text() else 0)
        self.details.setMinimumHeight(self.details.sizeHint().height() if self.details.text() else 0)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        self._fit_text()

    def _choose(self, index: int, *_) -> None:
        self.candidate_chosen.emit(index)

    def show_message(self, text: str, ok: bool = True) -> None:
        """A step's outcome on the message line (green, or orange when it found a problem)."""
        self.status.setText(
            f"<span style='color:{'#5fd35f' if ok else '#ffb347'}'>{html.escape(text, quote=False)}</span>"
        )
        self._fit_text()

    def show_error(self, text: str) -> None:
        self.status.setText(f"<span style='color:#ff6b6b'>{html.escape(text, quote=False)}</span>")
        self._fit_text()

    def clear_message(self) -> None:
        """The message line emptied: what it said was about a step the session has moved past (a new result, a
        stored correction), and under a new verdict an old "the last solve failed" reads as this one's."""
        self.status.setText("")
        self._fit_text()

    def refresh(self) -> None:
        model = self.model
        r = model.result.estimate
        if r is not self._shown:
            self._shown = r
            self.clear_message()
        while self.candidates.count():
            w = self.candidates.takeAt(0).widget()
            if w is not None:
                w.deleteLater()
        if r is None:
            self.verdict.setText("No solve yet. Pick at least %d pairs, then Calibrate." % model.required_pairs)
            self._fit_text()
            self.details.setText("")
            self.chart.set_values([])
            return
        sol = r.solution
        verdict = model.result.verdict
        stale = model.stale_reason
        if stale:
            text = (
                f"<span style='color:#9a9a9a'><b>FROM AN EARLIER STATE</b></span> - {html.escape(stale, quote=False)}"
            )
            text += (
                "<br><span style='color:#9a9a9a'>it was: "
                f"{html.escape(verdict.text if verdict else sol.status.value, quote=False)}</span>"
            )
        else:
            color = _VERDICT_COLORS[verdict.verdict if verdict else Verdict(sol.status.value)]
            word = (verdict.verdict.value if verdict else sol.status.value).upper()
            text = f"<span style='color:{color}'><b>{word}</b></span>"
            reasons = list(verdict.reasons) if verdict else ([sol.reason] if sol.reason else [])
            if sol.reason and sol.reason not in reasons:
                reasons.append(sol.reason)
            if reasons:
                text += " - " + html.escape("; ".join(reasons), quote=False)
        for w in sol.warnings:
            text += f"<br><span style='color:#ccb'>note: {html.escape(w, quote=False)}</span>"
        self._elsewhere = self._solved_elsewhere()
        if self._elsewhere:
            text += (
                "<br><span style='color:#ff9a30'>solved from another robot pose than the robot's now (the pairs' "
                "frame): it describes that pose</span>"
            )
        self.verdict.setText(text)
        self._fit_text()
        d, rv, sd, sr = r.displacement_mm, r.rotation_deg, r.std_displacement_mm, r.std_rotation_deg
        cam = r.cam2world_measured[:3, 3]
        self.details.setText(
            "<table cellspacing=4>"
            f"<tr><td>end-effector displacement</td><td>dx {d[0]:+.2f}</td><td>dy {d[1]:+.2f}</td><td>dz {d[2]:+.2f} "
            f"mm</td><td>|d| {np.linalg.norm(d):.2f} mm</td></tr>"
            f"<tr><td>1-sigma</td><td>{sd[0]:.2f}</td><td>{sd[1]:.2f}</td><td>{sd[2]:.2f} mm</td><td></td></tr>"
            f"<tr><td>rotation (base axes)</td><td>rx {rv[0]:+.3f}</td><td>ry {rv[1]:+.3f}</td><td>rz {rv[2]:+.3f} "
            f"deg</td><td>{np.linalg.norm(rv):.3f} deg</td></tr>"
            f"<tr><td>1-sigma</td><td>{sr[0]:.3f}</td><td>{sr[1]:.3f}</td><td>{sr[2]:.3f} deg</td><td></td></tr>"
            f"<tr><td>camera (base frame)</td><td>{cam[0]:.1f}</td><td>{cam[1]:.1f}</td><td>{cam[2]:.1f} "
            "mm</td><td></td></tr>"
            f"<tr><td>RMS residual</td><td>{sol.rms_px:.2f} px</td><td>{len(sol.residuals_px)} "
            f"{'edge samples' if sol.method == 'edges' else 'pairs'}</td>"
            f"<td>{'on the edges' if sol.method == 'edges' else f'{sol.iterations} iterations'}</td><td></td></tr>"
            "</table>"
        )
        self._fit_text()
        numbers = model.result.solved_numbers
        present = {p.number for p in model.pairs.usable()}
        # bars only for pairs that still exist as they were solved; a stale result shows none
        bars = (
            []
            if stale
            else [
                (str(n), float(e), float(l))
                for n, e, l in zip(numbers, sol.residual_norms_px, sol.leave_one_out_px)
                if n in present
            ]
        )
        self.chart.set_values(bars)
        if sol.status is SolveStatus.AMBIGUOUS:
            for i, c in enumerate(sol.candidates):
                button = QPushButton(
                    f"Use solution {i + 1} ({c.rms_px:.2f} "
                    f"px{'' if c.distance_to_prior_mm is None else f', {c.distance_to_prior_mm:.0f} mm from model'})"
                )
                button.setObjectName(f"candidate_{i}")
                button.setCheckable(True)
                button.setChecked(i == model.result.chosen_candidate)
                button.clicked.connect(functools.partial(self._choose, i))
                self.candidates.addWidget(button)
