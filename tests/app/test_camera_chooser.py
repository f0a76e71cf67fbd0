"""*File > Open camera...* through the real dialog: a folder of images becomes the window's camera while it runs; a
scheme nobody handles is refused with the installed ones named and the running camera goes on; a camera that cannot
be opened says so and the window stays up; the spec is offered again next time."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
from PySide6.QtWidgets import QInputDialog


def _choose(qtbot, win, spec: str) -> None:
    """Open the dialog from the File menu's action, type the spec and press OK, as an operator does."""
    chooser = win.files.camera
    chooser.action.trigger()
    dialog = chooser.dialog
    qtbot.waitUntil(dialog.isVisible, timeout=5_000)
    assert isinstance(dialog, QInputDialog) and dialog.isComboBoxEditable()
    dialog.setTextValue(spec)
    dialog.accept()


def test_a_camera_is_chosen_while_the_window_runs(qtbot, window, tmp_path):
    win, wb = window, window.workbench
    folder = tmp_path / "shots"
    folder.mkdir()
    for k in range(3):
        cv2.imwrite(str(folder / f"shot_{k}.png"), np.full((240, 320, 3), 200, np.uint8))
    old_worker = win.worker
    _choose(qtbot, win, str(folder))
    qtbot.waitUntil(
        lambda: wb.observations.latest is not None and wb.observations.latest.image.shape == (240, 320, 3),
        timeout=10_000,
    )
    assert win.worker is not old_worker and not old_worker.isRunning()  # the old camera was stopped, not left reading
    assert float(wb.observations.latest.image.mean()) == 200.0
    qtbot.waitUntil(
        lambda: win.files.camera.recent()[:1] == [str(folder)], timeout=5_000
    )  # it gave a frame: remembered
    # a scheme nobody handles: refused by name, the folder camera goes on
    running = win.worker
    _choose(qtbot, win, "gopro://cam1")
    assert (
        "no camera connector for 'gopro://cam1'" in win.results.status.text()
        and "installed:" in win.results.status.text()
    )
    assert win.worker is running and running.isRunning()
    # a camera that is not there: said in the results panel, the window stays up
    _choose(qtbot, win, str(tmp_path / "no_such_clip.mp4"))
    qtbot.waitUntil(lambda: "cannot open the camera" in win.results.status.text(), timeout=10_000)
    assert "no such video file" in win.results.status.text() and win.isVisible()
    # next time the dialog offers the camera that worked, not the ones that did not
    win.files.camera.action.trigger()
    dialog = win.files.camera.dialog
    qtbot.waitUntil(dialog.isVisible, timeout=5_000)
    assert dialog.comboBoxItems() == [str(folder)]
    out = Path(__file__).resolve().parents[1] / "output"
    out.mkdir(exist_ok=True)
    dialog.grab().save(str(out / "camera_chooser.png"))  # looked at
    dialog.reject()
