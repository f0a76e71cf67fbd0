"""The workflow's actions as the operator triggers them: the command panel's buttons and the menus'
entries (Accept, Delete, Undo, Redo, Calibrate, Store, Verify, the moves, Simulate, Add location, a
candidate chosen). Each calls one part of the core and says its answer on the status bar; a refused one
goes to ``show_error``. The enabled state of Undo, Redo and Calibrate follows the session's events.

The window builds the layout and the menus; it adds these actions to its menus and owns nothing of the
workflow itself."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QWidget

from app.gui.error_boundary import guarded
from app.gui.store_correction import store_with_consent
from calib_core.operator.move_preview import MoveNeedsConfirmation


class WorkflowActions(QObject):
    """Given the core's parts the actions work on: the calibration ``session`` (its undo stack and pairs enable the
    buttons), ``picking`` (accept, delete, calibrate), ``moves`` and the ``arm`` (the moves, Stop, a move's end),
    the correction ``desk`` (Store, Verify), the cell ``editor`` (Add location), ``task_count()`` (the cell's task
    locations, to name a new one) and the core's own commands ``undo()``, ``redo()`` and ``choose_candidate(i)`` (each
    lets go of the pair being made or records the choice); and the window's: ``commands``, the command panel whose
    buttons trigger these; ``table`` (its selected pair is the one deleted), ``results`` (a chosen candidate,
    Verify's answer), ``overview`` (a move's preview and its *Move* button, Simulate's path); ``say(text, ms)`` writes
    the status bar; ``show_error(text)`` shows a refusal; ``parent``: where the store dialogs open."""

    def __init__(
        self,
        *,
        session,
        picking,
        moves,
        arm,
        desk,
        editor,
        task_count: Callable[[], int],
        undo: Callable[[], str | None],
        redo: Callable[[], str | None],
        choose_candidate: Callable[[int], None],
        commands,
        table,
        results,
        overview,
        say: Callable[[str, int], None],
        show_error: Callable[[str], None],
        parent: QWidget,
    ):
        super().__init__(parent)
        self._session, self._picking, self._moves, self._desk, self._editor = session, picking, moves, desk, editor
        self._task_count, self._undo, self._redo = task_count, undo, redo
        self.commands, self.table, self.results, self.overview = commands, table, results, overview
        self.say, self.show_error, self.parent_widget = say, show_error, parent
        self.report = guarded(show_error)
        self.undo_action = QAction("&Undo", parent, shortcut=QKeySequence.StandardKey.Undo, triggered=self.undo)
        self.redo_action = QAction("&Redo", parent, shortcut=QKeySequence.StandardKey.Redo, triggered=self.redo)
        self.delete_action = QAction(
            "&Delete pair", parent, shortcut=QKeySequence.StandardKey.Delete, triggered=self.delete
        )
        self.accept_action = QAction(
            "&Accept pair", parent, shortcut=QKeySequence("Ctrl+Return"), triggered=self.accept
        )
        self.calibrate_action = QAction("&Calibrate", parent, shortcut=QKeySequence("F5"), triggered=self.calibrate)
        self.store_action = QAction("&Store correction", parent, triggered=self.store)
        self.stop_action = QAction(
            "&Stop the robot",
            parent,
            shortcut=QKeySequence("Esc"),
            triggered=lambda: self.report(moves.stop_robot)(),
        )
        self.stop_action.setShortcutContext(Qt.ShortcutContext.ApplicationShortcut)  # Esc stops the robot from any pane
        self.approach_action = QAction("Go to &approach", parent, triggered=lambda: self.go(approach=True))
        self.corrected_action = QAction(
            "Go to task, &corrected", parent, triggered=lambda: self.go(approach=False, corrected=True)
        )
        c = commands
        c.accept.clicked.connect(self.accept)
        c.delete.clicked.connect(self.delete)
        c.undo.clicked.connect(self.undo)
        c.redo.clicked.connect(self.redo)
        c.calibrate.clicked.connect(self.calibrate)
        c.store.clicked.connect(self.store)
        c.go_approach.clicked.connect(lambda: self.go(approach=True))
        c.go_task.clicked.connect(lambda: self.go(approach=False))
        c.go_task_here.clicked.connect(lambda: self.go(approach=False))
        c.go_corrected.clicked.connect(lambda: self.go(approach=False, corrected=True))
        c.go_uncorrected.clicked.connect(lambda: self.go(approach=False, corrected=False))
        c.verify.clicked.connect(self.report(self._verify))
        c.animate.clicked.connect(self.report(self._animate))
        c.add_location.clicked.connect(self.report(self.add_location))
        results.candidate_chosen.connect(self.report(choose_candidate))
        arm.move_finished.connect(self._move_finished)
        session.undo.changed.connect(self.update)
        session.pairs.changed.connect(self.update)  # pairs also change outside the undo stack (replay, workspace)
        self.update()

    def update(self, *_) -> None:
        """Undo and Redo name what they would do; Calibrate is enabled with enough usable pairs."""
        undo = self._session.undo
        self.undo_action.setEnabled(undo.can_undo)
        self.redo_action.setEnabled(undo.can_redo)
        self.undo_action.setText(f"&Undo {undo.undo_label}" if undo.undo_label else "&Undo")
        self.redo_action.setText(f"&Redo {undo.redo_label}" if undo.redo_label else "&Redo")
        self.commands.undo.setEnabled(undo.can_undo)
        self.commands.redo.setEnabled(undo.can_redo)
        self.commands.calibrate.setEnabled(self._session.can_calibrate)

    def accept(self) -> None:
        self.report(lambda: self.say(f"pair {self._picking.accept_pair()} accepted", 5000))()

    def delete(self) -> None:
        self.report(lambda: self._picking.delete_pair(self.table.selected_number()))()

    def undo(self) -> None:
        label = self._undo()
        self.say(f"undone: {label}" if label else "nothing to undo", 5000)

    def redo(self) -> None:
        label = self._redo()
        self.say(f"redone: {label}" if label else "nothing to redo", 5000)

    def calibrate(self) -> None:
        self.report(self._calibrate)()

    def _calibrate(self) -> None:
        result = self._picking.calibrate()
        s = result.solution
        self.say(
            f"calibrated: {s.status.value}, RMS {s.rms_px:.2f} px, displacement "
            f"{np.linalg.norm(result.displacement_mm):.2f} mm",
            10000,
        )

    def store(self) -> None:
        self.report(store_with_consent)(self.parent_widget, self._desk, lambda text: self.say(text, 5000))

    def _verify(self) -> None:
        v = self._desk.verify()
        self.results.show_message(v.text, ok=v.ok)

    def go(self, *, approach: bool, corrected: bool = False) -> None:
        self.move(lambda confirmed: self._moves.go_to_task(approach=approach, corrected=corrected, confirmed=confirmed))

    def move(self, send: Callable[[object], object]) -> None:
        """Send a move (``send(confirmed)`` calls the core). The core previews it in the overview; one
        that needs a confirmation waits there for *Move*; a refused one says why."""
        self.report(self._move)(send)

    def _move(self, send: Callable[[object], object]) -> None:
        try:
            send(False)
        except MoveNeedsConfirmation as exc:
            confirmation = exc.confirmation  # the name ``exc`` is gone once the except block ends
            self.overview.show_preview(exc.preview, lambda: self.report(send)(confirmation))  # void after a Stop
            self.say(f"{exc}: press Move in the overview to send it", 15000)

    def _move_finished(self, what: str, error: str) -> None:
        if error:
            self.show_error(f"move to {what} failed: {error}")
        else:
            self.say(f"arrived at {what}", 8000)

    def _animate(self) -> None:
        path = self._moves.simulate_approach()
        self.commands.sim_status.setText(path.text)
        self.overview.play_path(list(path.joints_deg))

    def add_location(self, name: str | None = None) -> None:
        name = name or f"location_{self._task_count() + 1}"
        self._editor.add_task_location(name)
        self.say(f"task location {name} added at the current pose", 5000)
