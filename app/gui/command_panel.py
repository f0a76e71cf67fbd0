"""The command panel with the original's four modes: programming, simulation, calibration, execution."""

from __future__ import annotations

import numpy as np

from PySide6.QtCore import QSignalBlocker, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QLabel,
    QListWidget,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from app.gui.buttons import button
from app.gui.error_boundary import attempt
from calib_core.operator.panes.commands import CommandsPaneModel


class CommandPanel(QTabWidget):
    """The panel binds what only sets the session or the task to the core itself (target, solve options,
    task location and its approach, Clear) and shows what they hold; the actions that need the window
    (moves with their confirmation, dialogs, the status bar) are connected by the main window.
    ``error(text)``: a setting the core refused, and why."""

    error = Signal(str)

    def __init__(self, model: CommandsPaneModel, parent=None):
        super().__init__(parent)
        self.model = model
        self.setMinimumWidth(250)
        # Six tabs (the paper's four modes, Vision and Cell) fit the panel without scroll arrows.
        self.setStyleSheet("QTabBar::tab { padding: 4px 5px; }")
        self.tabBar().setUsesScrollButtons(False)
        # Short verbs for the paper's four modes (programming, simulation, calibration, execution) and Vision,
        # so all five tabs fit the panel without scroll arrows.

        # Programming
        prog = QWidget()
        pl = QVBoxLayout(prog)
        pl.addWidget(QLabel("Task locations"))
        self.tasks = QListWidget()
        self.tasks.setObjectName("tasks")
        for name in model.task_names:
            self.tasks.addItem(name)
        pl.addWidget(self.tasks, 1)
        approach_row = QFormLayout()
        self.approach = QDoubleSpinBox()
        self.approach.setObjectName("approach_mm")
        self.approach.setRange(0.0, 1000.0)
        self.approach.setDecimals(1)
        self.approach.setSingleStep(10.0)
        self.approach.setSuffix(" mm")
        self.approach.setKeyboardTracking(False)  # one undoable edit per value, not one per keystroke
        self.approach.setToolTip("How far back along the tool's z axis the robot stops before the task pose")
        approach_row.addRow("Approach", self.approach)
        pl.addLayout(approach_row)
        self.go_approach = button("Go to approach", "go_approach", "IK to the approach pose, then move the robot (MVJ)")
        self.go_task = button("Go to task", "go_task", "IK to the task pose itself, without correction")
        self.add_location = button("Add location from current pose", "add_location")
        for b in (self.go_approach, self.go_task, self.add_location):
            pl.addWidget(b)
        self.addTab(prog, "Program")

        # Simulation
        sim = QWidget()
        sl = QVBoxLayout(sim)
        sl.addWidget(QLabel("Animate the planned motion in CAD (the robot does not move)."))
        self.animate = button("Animate to selected task", "animate")
        sl.addWidget(self.animate)
        self.sim_status = QLabel("")
        self.sim_status.setWordWrap(True)
        sl.addWidget(self.sim_status)
        sl.addStretch(1)
        self.addTab(sim, "Simulate")

        # Calibration
        cal = QWidget()
        cl = QVBoxLayout(cal)
        # the first step of a calibration, where the operator is: the camera sees the target only at its task
        self.go_task_here = button(
            "Go to task",
            "calibrate_go_task",
            "Move the robot to the selected task location: the camera then sees the target",
        )
        cl.addWidget(self.go_task_here)
        form = QFormLayout()
        self.target = QComboBox()
        self.target.setObjectName("target")
        for name in model.target_names:
            self.target.addItem(name)
        if model.target:
            self.target.setCurrentText(model.target)
        form.addRow("Target object", self.target)
        cl.addLayout(form)
        steps = QGroupBox("Point pairs")
        sl2 = QVBoxLayout(steps)
        self.hint = QLabel("Point: click a feature in the virtual camera, then the same point on the camera image.")
        self.hint.setWordWrap(True)
        sl2.addWidget(self.hint)
        self.find_points = button(
            "Find points (F6)",
            "find_points",
            "Find the target's features on the camera image and propose them as pairs",
        )
        sl2.addWidget(self.find_points)
        self.accept = button(
            "Accept pair",
            "accept",
            "Keep the current pair (Ctrl+Return); clicking the image again moves its 2D point until then",
        )
        self.delete = button("Delete pair", "delete")
        self.clear = button("Clear all", "clear")
        self.undo = button("Undo", "undo")
        self.redo = button("Redo", "redo")
        for b in (self.accept, self.delete, self.clear, self.undo, self.redo):
            sl2.addWidget(b)
        cl.addWidget(steps)
        self.estimate_focal = QCheckBox("Estimate focal lengths (4+ pairs)")
        self.robust = QCheckBox("Robust (flag mis-clicks)")
        cl.addWidget(self.estimate_focal)
        cl.addWidget(self.robust)
        self.calibrate = button("Calibrate", "calibrate", "Solve the camera pose (F5)")
        self.calibrate.setStyleSheet("font-weight: bold; padding: 6px;")
        self.store = button("Store correction", "store", "Store the displacement for the current task location")
        cl.addWidget(self.calibrate)
        cl.addWidget(self.store)
        cl.addStretch(1)
        self.addTab(cal, "Calibrate")

        # Execution
        ex = QWidget()
        el = QVBoxLayout(ex)
        self.monitoring = QCheckBox("Monitoring (CAD follows the robot)")
        self.monitoring.setChecked(True)
        self.live = QCheckBox("Live (camera video)")
        self.live.setChecked(True)
        el.addWidget(self.monitoring)
        el.addWidget(self.live)
        self.go_corrected = button(
            "Go to task, corrected", "go_corrected", "Move to the task location with its stored correction"
        )
        self.go_uncorrected = button("Go to task, uncorrected", "go_uncorrected")
        el.addWidget(self.go_corrected)
        el.addWidget(self.go_uncorrected)
        self.verify = button(
            "Verify: look again",
            "verify",
            "After Go to task, corrected: pick the pairs from there, then Verify reports how far the tool still is "
            "from the task location and whether the two looks agree",
        )
        el.addWidget(self.verify)
        self.corrections = QLabel("No corrections stored.")
        self.corrections.setWordWrap(True)
        el.addWidget(self.corrections)
        el.addStretch(1)
        self.addTab(ex, "Execute")
        self.setCurrentIndex(2)
        model.task_changed.connect(self._sync_tasks)
        model.scene_changed.connect(self._sync_targets)
        self._bind()

    def _bind(self) -> None:
        def run(fn, *args):
            attempt(self.error.emit, fn, *args)

        model = self.model
        self.clear.clicked.connect(lambda: run(model.clear_pairs))
        self.target.currentTextChanged.connect(lambda name: run(model.set_target, name))
        self.estimate_focal.toggled.connect(lambda on: run(model.set_option, "estimate_focal", on))
        self.robust.toggled.connect(lambda on: run(model.set_option, "robust", on))
        model.options_changed.connect(self.show_option)  # an undo sets the box back

        def task_chosen(name: str) -> None:
            if name:
                run(model.choose_task, name)

        self.tasks.currentTextChanged.connect(task_chosen)
        self.approach.valueChanged.connect(lambda mm: run(model.set_task_approach, mm))
        model.task_changed.connect(self._show_task)
        if model.task is not None:
            self._show_task(model.task.name)
        model.corrections_changed.connect(lambda task: self.show_corrections(model.corrections))

    def _show_task(self, name: str) -> None:
        """The approach box shows the chosen task location's approach distance (without sending it back)."""
        task = self.model.task
        if task is None or task.name != name:
            return
        with QSignalBlocker(self.approach):
            self.approach.setValue(task.approach_mm)

    def show_option(self, name: str, value: bool) -> None:
        """A solve option changed in the session (a click, an undo): the box shows it without sending it back."""
        box = {"estimate_focal": self.estimate_focal, "robust": self.robust}.get(name)
        if box is not None and box.isChecked() != value:
            with QSignalBlocker(box):
                box.setChecked(value)

    def show_corrections(self, table) -> None:
        """The stored corrections (a :class:`~calib_core.calibration.corrections.CorrectionTable`), one
        line per task location: the latest, how many were stored, its last verification."""
        lines = []
        for task in table.tasks():
            c = table.latest(task)
            history = table.history(task)
            measurements = sum(1 for h in history if h.kind == "measurement")
            kept = f"{len(history) - measurements} stored" + (
                f", {measurements} measurement{'s' if measurements > 1 else ''} at other poses" if measurements else ""
            )
            if c is None:
                lines.append(f"{task}: no correction ({kept})")
                continue
            line = (
                f"{task}: {np.linalg.norm(c.displacement_mm):.2f} mm, {np.linalg.norm(c.rotation_deg):.3f} deg ({kept}"
            )
            line += f", {c.verdict} confirmed)" if c.confirmation else ")"
            looks = table.verifications(task)
            if looks:
                v = looks[-1]
                line += (
                    f"; verified: {np.linalg.norm(v.remaining_mm):.2f} mm left (1-sigma "
                    f"{np.linalg.norm(v.std_remaining_mm):.2f}), {v.judgement}"
                )
            lines.append(line)
        self.corrections.setText("\n".join(lines) or "No corrections stored.")

    def _sync_tasks(self, name: str = "") -> None:
        """The task list follows the cell (a location added or undone)."""
        names = self.model.task_names
        if [self.tasks.item(i).text() for i in range(self.tasks.count())] == names:
            return
        current = self.tasks.currentItem().text() if self.tasks.currentItem() else None
        self.tasks.blockSignals(True)
        self.tasks.clear()
        self.tasks.addItems(names)
        if current in names:
            self.tasks.setCurrentRow(names.index(current))
        self.tasks.blockSignals(False)

    def _sync_targets(self) -> None:
        """The target choice follows the cell's components (one added or undone)."""
        names = self.model.target_names
        if [self.target.itemText(i) for i in range(self.target.count())] == names:
            return
        self.target.blockSignals(True)
        self.target.clear()
        self.target.addItems(names)
        if self.model.target in names:
            self.target.setCurrentText(self.model.target)
        self.target.blockSignals(False)
