"""The live window shared by the window tests: the controller simulator as a child process on a pty,
the simulated camera on its worker thread, images at 640 x 480 (the same workflow at a quarter of the
rendering cost). ``window`` has the robot's typical kinematic errors and the modelled camera mounting;
``live_window`` makes one with other errors."""

import os
import time

import pytest

from app.gui.cell_launcher import CellLauncher
from app.gui.main_window import MainWindow
from tests.app.windows import window_settings
from app.gui.workbench import Workbench
from videocal_sim.sim_site import simulated_cell
from videocal_sim.true_robot import RobotErrors


@pytest.fixture
def live_window(qtbot, tmp_path):
    made = []

    def make(errors: RobotErrors) -> MainWindow:
        cell, site = simulated_cell(errors=errors, image_scale=0.5)
        wb = Workbench(cell, site)
        wb.start_controller()
        win = MainWindow(wb, settings=window_settings(tmp_path, f"settings{len(made)}"))
        qtbot.addWidget(win)
        win.resize(1500, 950)
        win.start_camera(site.camera_factory(fps=10.0))
        win.show()
        qtbot.waitUntil(lambda: wb.link_up and win.camera.last_frame is not None, timeout=15_000)
        made.append(win)
        return win

    yield make
    for win in made:
        win.close()


@pytest.fixture
def window(live_window):
    typical = RobotErrors.typical(0)
    return live_window(
        RobotErrors(typical.joint_offsets_deg, typical.link_errors_mm, typical.base_xyz_mm, typical.base_rpy_deg)
    )


@pytest.fixture
def launcher(tmp_path):
    """Opens windows as `videocal gui` does on the simulated site: each cell with its own simulator."""
    return CellLauncher(
        lambda workcell, process=None: simulated_cell(workcell, process=process),
        settings=window_settings(tmp_path, "launcher"),
    )


@pytest.fixture
def offline_window(qtbot, tmp_path):
    """A window on the simulated cell with no controller and no camera started: for replays, which need neither."""
    wb = Workbench(*simulated_cell())
    win = MainWindow(wb, settings=window_settings(tmp_path))
    qtbot.addWidget(win)
    win.resize(1500, 950)
    win.show()
    yield win
    win.close()


MODAL_LIMIT_S = float(os.environ.get("VIDEOCAL_TEST_MODAL_LIMIT_S", "60"))
"""A modal dialog nobody answers for this long is closed and its test failed: the dialog's own event loop keeps
Python's timeout handler from ever running, and a test stuck there would hold up the whole run."""


@pytest.fixture(autouse=True)
def unanswered_dialogs():
    """Watches for a modal dialog left open (a question a test did not expect): closes it after
    :data:`MODAL_LIMIT_S` and fails the test, naming the dialog."""
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QApplication

    if QApplication.instance() is None:
        yield
        return
    seen: dict = {"widget": None, "since": 0.0}
    stuck: list[str] = []

    def check():
        widget = QApplication.activeModalWidget()
        if widget is None or widget is not seen["widget"]:
            seen["widget"], seen["since"] = widget, time.monotonic()
            return
        if time.monotonic() - seen["since"] > MODAL_LIMIT_S:
            text = getattr(widget, "text", lambda: "")()
            stuck.append(f"{type(widget).__name__} {widget.windowTitle()!r}: {text!r}")
            widget.close()
            if hasattr(widget, "reject"):
                widget.reject()
            seen["widget"] = None

    timer = QTimer()
    timer.timeout.connect(check)
    timer.start(500)
    yield
    timer.stop()
    if stuck:
        pytest.fail(f"a modal dialog waited {MODAL_LIMIT_S:g} s for an answer and was closed: {stuck[0]}")
