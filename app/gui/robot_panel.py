"""The Robot mode: calibrate the robot's geometry and its camera mounting from board views at many
poses. Plan the poses (reachable, collision-free paths, the whole board in view, chosen for what they
determine), preview the plan, run it (each move awaited, each view taken once the robot settled),
review the identification (what the views determine and what not), apply it to the cell's robot or
take it back, save it (YAML of the parameters, the calibrated URDF)."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QEventLoop, Qt
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QFileDialog,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressBar,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.gui.buttons import button
from app.gui.busy import busy
from app.gui.confirm import ask
from app.gui.error_boundary import guarded
from app.gui.tool_group import ToolGroup
from calib_core.operator.panes.robot import RobotPaneModel
from calib_core.errors import OperatorError
from calib_core.operator.calibration_run import VIA
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.target_spec import turn_ambiguity


class RobotPanel(QWidget):
    """``show_error`` puts a failed step's reason in the window; progress goes to the core's log (the
    messages (the status bar) and to the panel's own line."""

    def __init__(self, model: RobotPaneModel, show_error: Callable[[str], None], parent=None):
        super().__init__(parent)
        self.model = model
        guard = guarded(show_error)
        self.plan = None
        self.run = None
        self.result = None

        plan = QGroupBox("Plan")
        pl = QVBoxLayout(plan)
        self.spec = QLineEdit(DEFAULT_SPEC)
        self.spec.setToolTip(
            "a ChArUco or ArUco board: charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT[:legacy], "
            "aruco:COLSxROWS:MARKER_MM:GAP_MM:DICT"
        )
        pl.addWidget(self.spec)
        self.show_board = QCheckBox("Board in the simulated cell")
        self.show_board.setToolTip(
            "Put the board up where the cell's hand_eye_board says (the simulated camera sees it)"
        )
        self.show_board.toggled.connect(guard(lambda on: self.model.show_board(self._spec(), on)))
        pl.addWidget(self.show_board)
        row = QHBoxLayout()
        row.addWidget(QLabel("Poses"))
        self.poses = QSpinBox()
        self.poses.setRange(8, 200)
        self.poses.setValue(40)
        self.poses.setToolTip("How many poses to view the board from (30-40 determine a 6-axis robot well)")
        row.addWidget(self.poses)
        self.plan_button = button(
            "Plan poses",
            "robot_plan",
            "Choose reachable, collision-free poses that see the whole board and determine the parameters best",
        )
        self.plan_button.clicked.connect(guard(self.make_plan))
        row.addWidget(self.plan_button, 1)
        pl.addLayout(row)
        self.plan_text = QLabel("No plan yet.")
        self.plan_text.setWordWrap(True)
        pl.addWidget(self.plan_text)

        run = QGroupBox("Run")
        rl = QVBoxLayout(run)
        row = QHBoxLayout()
        self.run_button = button(
            "Run plan",
            "robot_run",
            "Drive the robot through the planned poses (MVJ), capturing a board view at each once the robot settled",
        )
        self.run_button.clicked.connect(guard(self.start_run))
        self.stop_button = button("Stop", "robot_stop", "Stop after the current move; the views taken so far are kept")
        self.stop_button.clicked.connect(guard(lambda: self.run.stop() if self.run is not None else None))
        row.addWidget(self.run_button, 2)
        row.addWidget(self.stop_button, 1)
        rl.addLayout(row)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        rl.addWidget(self.progress)
        self.run_text = QLabel("")
        self.run_text.setWordWrap(True)
        rl.addWidget(self.run_text)

        review = QGroupBox("Identify")
        vl = QVBoxLayout(review)
        self.identify_button = button(
            "Identify",
            "robot_identify",
            "The robot's joint placements and the camera mounting from the views (6 or more, 30-40 recommended)",
        )
        self.identify_button.clicked.connect(guard(self.identify))
        vl.addWidget(self.identify_button)
        self.fit_intrinsics = QCheckBox("Refine the camera's intrinsics with the robot")
        self.fit_intrinsics.setChecked(True)
        self.fit_intrinsics.setToolTip(
            "The board views correct fu, fv, cx, cy, k1, k2, p1, p2 together with the robot; Apply uses them too, "
            "Revert takes them back"
        )
        vl.addWidget(self.fit_intrinsics)
        self.result_text = QLabel("")
        self.result_text.setWordWrap(True)
        self.result_text.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        vl.addWidget(self.result_text)
        row = QHBoxLayout()
        self.apply_button = button(
            "Apply",
            "robot_apply",
            "Use the calibrated robot for the views, the solver's prior and every move from now on",
        )
        self.apply_button.clicked.connect(guard(self.apply))
        self.revert_button = button("Revert", "robot_revert", "Use the robot's model as loaded again")
        self.revert_button.clicked.connect(guard(self.revert))
        self.save_button = button(
            "Save...", "robot_save", "Save robot_calibration.yaml and the calibrated URDF into a folder"
        )
        self.save_button.clicked.connect(guard(self._save_dialog))
        for b in (self.apply_button, self.revert_button, self.save_button):
            row.addWidget(b)
        vl.addLayout(row)

        self.tool_group = ToolGroup(model.tool, show_error, self._refresh)
        layout = QVBoxLayout(self)
        layout.addWidget(plan)
        layout.addWidget(run)
        layout.addWidget(review)
        layout.addWidget(self.tool_group)
        layout.addStretch(1)
        self._refresh()

    def _spec(self):
        spec = parse_board(self.spec.text().strip())
        if not spec.unambiguous:
            raise OperatorError(turn_ambiguity(spec, "a robot calibration"))
        return spec

    def _refresh(self) -> None:
        running = self.run is not None and self.run.phase in ("moving", "settling")
        views = len(self.run.capture.views) if self.run is not None else 0
        self.plan_button.setEnabled(not running)
        self.run_button.setEnabled(self.plan is not None and bool(self.plan.joints_deg) and not running)
        self.stop_button.setEnabled(running)
        self.identify_button.setEnabled(views >= 6 and not running)
        self.apply_button.setEnabled(self.result is not None)
        self.save_button.setEnabled(self.result is not None)
        self.revert_button.setEnabled(self.model.can_revert)

    # --- plan and run --------------------------------------------------------------------------
    def make_plan(self) -> None:
        with busy(self, "planning the calibration poses ..."):
            self.plan = self.model.plan(self._spec(), self.poses.value())
        n = len(self.plan.joints_deg)
        why = "; ".join(f"{k}: {v}" for k, v in self.plan.rejected.items())
        seen = [c for c, _ in self.plan.cell_views if c != VIA]
        self.plan_text.setText(
            f"{n} board poses (of {self.plan.candidates} candidates) and {len(seen)} views of surveyed components "
            f"({', '.join(sorted(set(seen))) or 'none reachable'}), which tie the robot to the cell."
        )
        self.plan_text.setToolTip(
            "Every pose sees its target with the model, and every move from the one before is free of collisions."
            + (f" Left out: {why}." if why else "")
        )
        self.model.say(f"robot calibration: {n} poses planned")
        self._refresh()

    def start_run(self) -> None:
        if self.plan is None or not self.plan.joints_deg:
            raise OperatorError("plan the poses first")
        n = len(self.plan.joints_deg) + len(self.plan.cell_views)
        if not ask(
            self,
            "Drive the robot through the calibration poses?",
            f"The robot will move through {n} poses, one after the other, stopping at each "
            "until a view is taken. Every path was checked against the cell's collision bodies with the model. Keep "
            "the emergency stop at hand; "
            "Stop ends the run after the current move.",
            "Run",
        ):
            return
        self.run = self.model.run(self._spec(), self.plan.joints_deg, self.plan.cell_views)
        self.progress.setRange(0, n)
        self.progress.setValue(0)
        self.run.progress.connect(self._on_progress)
        self.run.finished.connect(lambda text: self._refresh())
        self.run.start()
        self._refresh()

    def _on_progress(self, p) -> None:
        self.progress.setValue(min(p.index, p.total))
        self.run_text.setText(p.text)
        self._refresh()

    # --- identify, apply, save -----------------------------------------------------------------
    def identify(self) -> None:
        if self.run is None:
            raise OperatorError("run the plan first: the identification needs the views it takes")

        def step(done: int, total: int, text: str) -> None:
            self.progress.setRange(0, total)
            self.progress.setValue(done)
            self.run_text.setText(text)
            QApplication.processEvents(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)  # drawn, not clicked twice

        before = (self.progress.maximum(), self.progress.value(), self.run_text.text())
        self.identify_button.setEnabled(False)
        try:
            with busy(self, "identifying the robot ..."):
                r = self.result = self.model.identify(
                    self.run.capture,
                    cell_frames=self.run.cell_frames,
                    with_intrinsics=self.fit_intrinsics.isChecked(),
                    progress=step,
                )
        finally:  # the run's own progress back (the panel says what the run did)
            self.progress.setRange(0, before[0])
            self.progress.setValue(before[1])
            self.run_text.setText(before[2])
            self._refresh()
        obs = r.observability
        lines = [
            f"<b>Robot</b> from {len(r.per_view_rms_px)} views "
            f"({sum(k.startswith('cell_') for k in r.per_view_rms_px)} of surveyed components): RMS "
            f"{r.start_rms_px:.2f} px with the model, {r.rms_px:.3f} px calibrated",
            f"{len(obs.identified)} of {len(r.names)} parameters identified (condition {obs.condition:.0f}); "
            f"{len(obs.directions)} combinations the views do not determine"
            + (f", e.g. {', '.join(f'{w:+.2f} {n}' for n, w in obs.directions[0][:3])}" if obs.directions else ""),
            f"{len(obs.correlations)} pairs correlated above 0.9"
            if obs.correlations
            else "no two parameters correlated above 0.9",
        ]
        worst = max(r.per_view_rms_px.items(), key=lambda kv: kv[1])
        lines.append(f"worst view {worst[0]}: {worst[1]:.3f} px")
        lines += [f"<span style='color:#e0a030'>warning: {w}</span>" for w in r.warnings]
        self.result_text.setText("<br>".join(lines))
        self._refresh()

    def apply(self) -> None:
        if self.result is None:
            raise OperatorError("identify first")
        self.model.apply(self.result)
        self._refresh()

    def revert(self) -> None:
        self.model.revert()
        self.tool_group.measured_tool = None
        self._refresh()

    def save(self, folder) -> None:
        if self.result is None:
            raise OperatorError("identify first")
        self.model.save(folder, self.result, self.tool_group.measured_tool)

    def _save_dialog(self) -> None:
        folder = QFileDialog.getExistingDirectory(self, "Save the robot calibration into")
        if folder:
            self.save(folder)
