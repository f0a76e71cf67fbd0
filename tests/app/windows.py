"""Helpers for the window tests."""

import time

import numpy as np
from PySide6.QtCore import QPoint, QPointF, QSettings, Qt, QTimer
from PySide6.QtWidgets import QApplication, QFileDialog, QMessageBox

from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference


def window_settings(folder, name: str = "settings") -> QSettings:
    """A window's settings in ``folder``, its autosaves there too (a test's windows never see another test's)."""
    settings = QSettings(str(folder / f"{name}.ini"), QSettings.Format.IniFormat)
    settings.setValue("files/autosave_dir", str(folder / f"{name}_autosave"))
    settings.setValue("window/ask_unsaved", False)  # a test that wants the question turns it on
    return settings


def wait_for_settled_frame(qtbot, win, timeout_ms: int = 15_000) -> None:
    """Wait until the camera's newest frame, captured after this call, is one the core accepts for
    picks: the robot had settled before it was captured (the predicate the core applies to a pick)."""
    wb = win.workbench
    since = time.monotonic()

    def settled() -> bool:
        frame = win.camera.last_frame_received
        return frame is not None and frame.t_host_s >= since and wb.observations.stillness(frame).settled

    qtbot.waitUntil(settled, timeout=timeout_ms)


def pick_pair(wb, component: str, feature, point_world_mm, pixel) -> int:
    """One pair through the core, as the panes' clicks make it (the image point on the held frame)."""
    wb.picking.pick_model_point(component, feature, point_world_mm)
    wb.picking.pick_image_point(pixel)
    return wb.picking.accept_pair()


def confirm_move_if_asked(qtbot, win) -> bool:
    """Press *Move* in the overview when the previewed move waits for a confirmation (a large joint
    change); True if it did."""
    button = win.overview.move_button
    if win.overview.preview_bar.isVisible() and button.isVisible():
        qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
        return True
    return False


def answer_next_question(qtbot, button_text: str) -> list:
    """Click ``button_text`` in the next modal question (a QMessageBox) as soon as it is up."""
    answered = []

    def look() -> None:
        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox):
            for b in box.buttons():
                if b.text().replace("&", "") == button_text:
                    answered.append(box.text())
                    b.click()
                    return
        QTimer.singleShot(20, look)

    QTimer.singleShot(0, look)
    return answered


def answer_questions(qtbot, button_texts: list[str]) -> list:
    """Click ``button_texts`` in the next modal questions, one question each, in order; returns the
    questions' texts as they were answered."""
    answered = []
    remaining = list(button_texts)

    def look() -> None:
        box = QApplication.activeModalWidget()
        if isinstance(box, QMessageBox) and box.text() not in answered[-1:]:
            for b in box.buttons():
                if b.text().replace("&", "") == remaining[0]:
                    answered.append(box.text())
                    remaining.pop(0)
                    b.click()
                    break
        if remaining:
            QTimer.singleShot(20, look)

    QTimer.singleShot(0, look)
    return answered


def go_and_settle(qtbot, win, button) -> None:
    """Press a move button, confirm the move if the overview asks, wait until it arrived and a frame
    captured after it has settled."""
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    qtbot.waitUntil(lambda: win.workbench.motion.motion.value == "arrived", timeout=30_000)
    wait_for_settled_frame(qtbot, win)


def pick_features(
    qtbot, win, features: list[str], component: str = "oru_1_fixture", off_px: dict | None = None
) -> None:
    """Pick each feature through the panes: on the virtual camera, then on the camera image where the
    truth puts it (the operator's eyes; ``off_px``: a feature's pick moved by (du, dv) px, a mis-pick), then
    Ctrl+Return."""
    wb = win.workbench
    fixture = wb.workcell.component(component)
    true_cam = wb.site.bed.true_cam2world(wb.joints_deg)
    win.camera.subpixel.setChecked(False)
    for name in features:
        p = apply(fixture.item2world, fixture.features[name])
        uv_model = project(apply(invert(wb.model_cam2world()), p[None]), win.virtual.intrinsics, distort=False)[0]
        x, y = win.virtual.view.image_to_widget(*uv_model)
        qtbot.mouseClick(win.virtual.view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x)), int(round(y))))
        uv = project(apply(invert(true_cam), p[None]), wb.intrinsics)[0] + np.asarray(
            (off_px or {}).get(name, (0.0, 0.0))
        )
        x, y = win.camera.view.image_to_widget(*uv)
        qtbot.mouseClick(win.camera.view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x)), int(round(y))))
        qtbot.keyClick(win, Qt.Key.Key_Return, Qt.KeyboardModifier.ControlModifier)
    assert len(wb.session.pairs.usable()) == len(features), win.results.status.text()


def click_image(qtbot, view, u, v, zoom=None):
    if zoom is not None:
        # The operator zooms in (mouse wheel) around the point before clicking it.
        view.set_zoom(zoom, QPointF(u, v))
    x, y = view.image_to_widget(u, v)
    qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x)), int(round(y))))


def go_to_task(qtbot, win):
    """The robot to the task location itself (uncorrected): the camera sees the fixture from there."""
    wb = win.workbench
    task = wb.task
    qtbot.mouseClick(win.commands.go_task, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    qtbot.waitUntil(
        lambda: np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), task.tcp2base)[0]) < 0.01, timeout=20_000
    )
    # A frame taken with the robot settled there, and the virtual camera redrawn there.
    wait_for_settled_frame(qtbot, win)
    qtbot.waitUntil(win.virtual.is_current, timeout=5_000)


def answer_file_dialog(path) -> list[str]:
    """Choose ``path`` in the next file dialog the window opens; the dialogs' titles are gathered."""
    asked = []

    def answer():
        dialog = QApplication.activeModalWidget()
        if isinstance(dialog, QFileDialog):
            asked.append(dialog.windowTitle())
            dialog.selectFile(str(path))
            dialog.accept()
        else:
            QTimer.singleShot(20, answer)

    QTimer.singleShot(0, answer)
    return asked
