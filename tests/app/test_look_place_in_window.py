"""The first hole through the real window: Go to approach, pick, Calibrate (OK), Store
correction. The look was made 200 mm from the task location: the window says so and offers to keep it
as a measurement; kept so, *Go to task, corrected* has no correction to execute and moves nothing."""

import numpy as np
from PySide6.QtCore import Qt

from tests.app.windows import answer_questions, go_and_settle, pick_features

FEATURES = [
    "plate_top_left",
    "plate_top_right",
    "plate_bottom_right",
    "plate_bottom_left",
    "boss_top_left",
    "boss_bottom_right",
]


def test_a_look_from_the_approach_is_kept_as_a_measurement_and_moves_nothing(qtbot, window):
    win, wb = window, window.workbench
    go_and_settle(qtbot, win, win.commands.go_approach)
    pick_features(qtbot, win, FEATURES)
    qtbot.keyClick(win, Qt.Key.Key_F5)
    assert wb.session.result.estimate is not None and wb.session.result.estimate.solution.status.value != "failed"
    asked = answer_questions(qtbot, ["Store as measurement"])
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    assert (
        asked and "cannot be oru_1_grasp's correction" in asked[0] and "200.0 mm" in asked[0] and "moves by" in asked[0]
    )
    table = wb.session.corrections
    assert table.latest(wb.task.name) is None and [c.kind for c in table.history(wb.task.name)] == ["measurement"]
    assert "no correction (0 stored, 1 measurement at other poses)" in win.commands.corrections.text()
    before, last_move = np.array(wb.joints_deg), wb.arm.pending_move
    qtbot.mouseClick(win.commands.go_corrected, Qt.MouseButton.LeftButton)
    assert "no stored correction for oru_1_grasp" in win.results.status.text(), win.results.status.text()
    assert wb.arm.pending_move is last_move and np.max(np.abs(wb.joints_deg - before)) < 1e-6


def test_cancel_stores_nothing(qtbot, window):
    win, wb = window, window.workbench
    go_and_settle(qtbot, win, win.commands.go_approach)
    pick_features(qtbot, win, FEATURES)
    qtbot.keyClick(win, Qt.Key.Key_F5)
    asked = answer_questions(qtbot, ["Cancel"])
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    assert asked and wb.session.corrections.history(wb.task.name) == []
    assert "nothing stored" in win.statusBar().currentMessage()
