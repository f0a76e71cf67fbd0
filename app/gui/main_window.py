"""The main window: it builds the layout and the menus from the panes and the workflow's actions
(:mod:`app.gui.workflow_actions`); each pane binds itself to the workbench."""

from __future__ import annotations

from PySide6.QtCore import QSettings, QTimer
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QMainWindow, QScrollArea

from app.gui.camera_pane import CameraPane
from app.gui.cell_panel import CellPanel
from app.gui.command_panel import CommandPanel
from app.gui.error_boundary import attempt, guarded
from app.gui.frame_worker import FrameWorker
from app.gui.overview_pane import OverviewPane
from app.gui.pairs_table import PairsTable
from app.gui.replay_bar import ReplayBar
from app.gui.results_panel import ResultsPanel
from app.gui.file_menu import FileMenu
from app.gui.found_points import FindPoints
from app.gui.message_status_bar import MessageStatusBar
from app.gui.status_line import StatusLine
from app.gui.virtual_pane import VirtualPane
from app.gui.robot_panel import RobotPanel
from app.gui.vision_panel import VisionPanel
from app.gui.window_layout import arrange_panes, restore_layout, save_layout
from app.gui.workbench import Workbench
from app.gui.workflow_actions import WorkflowActions
from calib_core.operator.panes.camera import CameraPaneModel
from calib_core.operator.panes.cell_editing import CellPaneModel
from calib_core.operator.panes.commands import CommandsPaneModel
from calib_core.operator.panes.overview import OverviewPaneModel
from calib_core.operator.panes.pairs import PairsTableModel
from calib_core.operator.panes.results import ResultsPaneModel
from calib_core.operator.panes.robot import RobotPaneModel
from calib_core.operator.panes.status import StatusLineModel
from calib_core.operator.panes.virtual_camera import VirtualPaneModel


VIRTUAL_EVERY_TICKS = 2  # the virtual camera follows a moving robot at 10 fps, the overview at 20


class MainWindow(QMainWindow):
    def __init__(self, workbench: Workbench, *, settings: QSettings | None = None, launcher=None):
        super().__init__()
        self.workbench = workbench
        self.launcher = launcher  # opens another cell in a new window (File > Open cell); None: this window's cell only
        self.settings = settings or QSettings("videocal", "videocal")
        self.setWindowTitle(f"videocal - {workbench.workcell.name}")
        self.setStatusBar(MessageStatusBar(self))  # (before anything says a word: a long message ends in an ellipsis)
        self.camera = CameraPane(
            CameraPaneModel(
                workbench.cell,
                workbench.frames,
                workbench.picking,
                workbench.session,
                workbench.arm,
                workbench.finder,
            )
        )
        self.virtual = VirtualPane(
            VirtualPaneModel(workbench.cell, workbench.session, workbench.arm, workbench.picking)
        )
        self.overview = OverviewPane(
            OverviewPaneModel(workbench.cell, workbench.session, workbench.arm, workbench.moves)
        )
        self.table = PairsTable(PairsTableModel(workbench.session))
        self.results = ResultsPanel(ResultsPaneModel(workbench.session, workbench.arm))
        self.commands = CommandPanel(
            CommandsPaneModel(workbench.cell, workbench.session, workbench.tasks, workbench.editor)
        )
        self.replay = ReplayBar(workbench.replay, lambda frame: workbench.frames.observe_frame(frame, replayed=True))
        self.vision = VisionPanel(
            workbench.vision,
            self.show_error,
            lambda q, what: self.actions.move(
                lambda confirmed: workbench.moves.move_joints(q, what, confirmed=confirmed)
            ),
            say=workbench.log.say,
        )
        self.vision.board_detected.connect(self.camera.set_board_corners)
        self.robot_calibration = RobotPanel(
            RobotPaneModel(workbench.robot_calibration, workbench.vision, workbench.tool, workbench.log),
            self.show_error,
        )
        self.cell_panel = CellPanel(
            CellPaneModel(workbench.cell, workbench.editor, workbench.session, workbench.arm, workbench.log),
            lambda fn, *a, **k: attempt(self.show_error, fn, *a, **k),
        )
        for panel, title in ((self.vision, "Vision"), (self.robot_calibration, "Robot"), (self.cell_panel, "Cell")):
            scroll = QScrollArea()  # the panels are taller than a small screen
            scroll.setWidgetResizable(True)
            scroll.setWidget(panel)
            self.commands.addTab(scroll, title)
        self.actions = WorkflowActions(
            session=workbench.session,
            picking=workbench.picking,
            moves=workbench.moves,
            arm=workbench.arm,
            desk=workbench.desk,
            editor=workbench.editor,
            task_count=lambda: len(workbench.workcell.task_locations),
            undo=workbench.undo,
            redo=workbench.redo,
            choose_candidate=workbench.choose_candidate,
            commands=self.commands,
            table=self.table,
            results=self.results,
            overview=self.overview,
            say=lambda text, ms: self.statusBar().showMessage(text, ms),
            show_error=self.show_error,
            parent=self,
        )
        self._joints_dirty = False  # joints moved since the virtual camera was last checked
        self._ticks = 0
        self.worker: FrameWorker | None = None
        arrange_panes(self)
        self._build_menus()
        self._build_status()
        self._connect()
        restore_layout(self, self.settings)
        self._redraw = QTimer(self)
        self._redraw.setInterval(50)  # overview and virtual camera at up to 20 fps, only when something changed
        self._redraw.timeout.connect(self._redraw_views)
        self._redraw.start()
        self.virtual.refresh()
        self.overview.refresh()
        self.files.start_autosave()

    def _build_menus(self) -> None:
        wb = self.workbench
        self.files = FileMenu(
            self,
            self.menuBar().addMenu("&File"),
            files=wb.files,
            editor=wb.editor,
            recording=wb.recording,
            session=wb.session,
            revision=lambda: wb.revision,
            cell_folder=lambda: wb.workcell.path.parent,
        )
        self.play_action = QAction(
            "Play/pause replay", self, shortcut=QKeySequence("Ctrl+Space"), triggered=self.replay.toggle_play
        )
        self.addAction(self.play_action)
        edit = self.menuBar().addMenu("&Edit")
        for a in (
            self.actions.undo_action,
            self.actions.redo_action,
            self.actions.delete_action,
            self.actions.accept_action,
        ):
            edit.addAction(a)
        cal = self.calibration_menu = self.menuBar().addMenu("&Calibration")
        cal.addAction(self.actions.calibrate_action)
        cal.addAction(self.actions.store_action)
        view = self.menuBar().addMenu("&View")
        view.addAction(
            QAction("&Reset camera zoom", self, shortcut=QKeySequence("Ctrl+0"), triggered=self.camera.view.reset_view)
        )
        view.addAction(
            QAction(
                "&Fit the overview to the cell",
                self,
                shortcut=QKeySequence("Ctrl+F"),
                triggered=lambda: (self.overview.fit_view(), self.overview.refresh()),
            )
        )
        robot = self.menuBar().addMenu("&Robot")
        for a in (self.actions.stop_action, self.actions.approach_action, self.actions.corrected_action):
            robot.addAction(a)

    def _build_status(self) -> None:
        wb = self.workbench
        self.status_line = StatusLine(
            self.statusBar(),
            StatusLineModel(wb.arm, wb.session, wb.frames, wb.recording, lambda: wb.link),
            camera_state=self._camera_state,
            parent=self,
        )

    def _connect(self) -> None:
        wb = self.workbench
        c = self.commands
        self.report = guarded(self.show_error)
        self.virtual.pick_rejected.connect(self.show_error)
        self.virtual.feature_picked.connect(self.report(self.cell_panel.feature_clicked))
        self.cell_panel.feature_mode_changed.connect(self.virtual.set_feature_component)
        self.camera.pick_rejected.connect(self.show_error)
        self.camera.pair_selected.connect(self.table.select_number)
        self.virtual.pair_selected.connect(self.table.select_number)
        c.error.connect(self.show_error)
        c.live.toggled.connect(self._live_toggled)
        wb.arm.joints_changed.connect(self._on_joints)
        self.replay.closed.connect(self._replay_closed)
        wb.log.message.connect(lambda text: self.statusBar().showMessage(text, 8000))
        self.finder = FindPoints(wb.finder, self, self.show_error, self.statusBar().showMessage)
        self.calibration_menu.addAction(self.finder.action)
        self.commands.find_points.clicked.connect(self.finder.run)

    def _live_toggled(self, on: bool) -> None:
        if self.worker is not None:
            self.worker.paused = not on

    # --- camera ----------------------------------------------------------------------------
    def start_camera(self, make_source) -> None:
        self.worker = FrameWorker(make_source, self)
        self.worker.frame.connect(self.workbench.frames.observe_frame)  # the camera pane shows what the core observed
        self.worker.failed.connect(self.show_error)
        self.worker.waiting.connect(lambda text: self.statusBar().showMessage(text, 5000))
        self.worker.start()

    # --- actions ---------------------------------------------------------------------------
    def show_error(self, text: str) -> None:
        self.results.show_error(text)
        self.statusBar().showMessage(text, 15000)

    def _replay_closed(self) -> None:
        self.commands.live.setChecked(True)

    # --- updates ---------------------------------------------------------------------------
    def _on_joints(self, q) -> None:
        if self.commands.monitoring.isChecked():
            self.overview.mark_dirty()
            self._joints_dirty = True

    def _redraw_views(self) -> None:
        # While the robot moves, the virtual camera (for picking, on a still robot) redraws at half the
        # overview's rate: on a CPU renderer the two renders of a vendor robot do not fit one 50 ms tick.
        self._ticks += 1
        if self._joints_dirty and self._ticks % VIRTUAL_EVERY_TICKS == 0:
            self._joints_dirty = False
            self.virtual.refresh_if_moved()
        self.overview.refresh()

    def _update_status(self) -> None:
        self.status_line.update()

    def _camera_state(self) -> tuple:
        return self.camera.last_frame_received, self.worker, self.replay.playback is not None

    # --- life cycle ------------------------------------------------------------------------
    def closeEvent(self, event) -> None:
        if not self.files.may_close():
            event.ignore()
            return
        save_layout(self, self.settings)
        self._redraw.stop()
        self.files.autosave.finish()  # unsaved work stays recoverable; a closed window writes nothing more
        self.status_line.timer.stop()
        self.replay.pause()
        self.replay.release_file()  # a bag stays open while it is replayed
        if self.worker is not None:
            self.worker.stop()
        self.virtual.close_renderer()
        self.overview.renderer.close()
        self.camera.close_renderer()
        self.workbench.close()
        super().closeEvent(event)
