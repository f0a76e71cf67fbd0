"""Esc said "stop sent to the controller" but the Move prompt stayed armed, and *Move* then
moved the robot. A Stop now voids every prompt waiting; a confirmation given before it moves nothing."""

import numpy as np
import pytest
from PySide6.QtCore import Qt

from calib_core.calibration.errors import CalibrationError
from calib_core.operator.move_preview import MoveNeedsConfirmation


def _far_joints(wb):
    q = np.array(wb.joints_deg, dtype=float)
    q[0] += wb.workcell.safety.confirm_joint_change_deg + 10.0  # a joint change that needs a confirmation
    return q


def test_esc_withdraws_a_waiting_move_prompt(qtbot, window):
    win, wb = window, window.workbench
    q, before = _far_joints(wb), np.array(wb.joints_deg)
    win.actions.move(lambda confirmed: wb.moves.move_joints(q, "far", confirmed=confirmed))
    assert win.overview.move_button.isVisible() and "waiting for your confirmation" in win.overview.preview_text.text()
    qtbot.keyClick(win, Qt.Key.Key_Escape)
    assert "stop sent" in win.statusBar().currentMessage() or "stop sent" in win.results.status.text()
    assert not win.overview.preview_bar.isVisible() and not win.overview.move_button.isVisible()
    qtbot.mouseClick(win.overview.move_button, Qt.MouseButton.LeftButton)  # hidden: the click goes nowhere
    assert wb.motion.motion.value != "moving" and np.max(np.abs(wb.joints_deg - before)) < 1e-6
    # Asked again, Move sends it.
    win.actions.move(lambda confirmed: wb.moves.move_joints(q, "far", confirmed=confirmed))
    qtbot.mouseClick(win.overview.move_button, Qt.MouseButton.LeftButton)
    # arrived (the controller's DON) and the joints there: on a loaded machine the last sample may follow the DON
    qtbot.waitUntil(
        lambda: wb.motion.motion.value == "arrived" and np.max(np.abs(wb.joints_deg - q)) < 1e-3, timeout=30_000
    )


def test_a_confirmation_given_before_a_stop_moves_nothing(qtbot, window):
    wb = window.workbench
    q = _far_joints(wb)
    with pytest.raises(MoveNeedsConfirmation) as asked:
        wb.moves.move_joints(q, "far")
    wb.moves.stop_robot()
    with pytest.raises(CalibrationError, match="stopped after this move was asked for"):
        wb.moves.move_joints(q, "far", confirmed=asked.value.confirmation)
    assert wb.motion.motion.value != "moving"
    with pytest.raises(MoveNeedsConfirmation) as again:  # asked again, answered: it goes
        wb.moves.move_joints(q, "far")
    wb.moves.move_joints(q, "far", confirmed=again.value.confirmation)
    qtbot.waitUntil(lambda: wb.motion.motion.value == "arrived", timeout=30_000)
