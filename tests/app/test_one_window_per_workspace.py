"""Two windows on one workspace file saved over each other's work without a word. A window that has the workspace
open (or has saved it) holds it; a second window that opens or saves the same file is told who holds it, and
nothing is written; once the first window closes, the file is free."""

from __future__ import annotations
from calib_core.calibration.commands import AddPoint3D

import json

from app.gui.main_window import MainWindow
from app.gui.workbench import Workbench
from tests.app.windows import window_settings
from videocal_sim.sim_site import simulated_cell


def test_a_second_window_is_told_and_writes_nothing(qtbot, offline_window, tmp_path):
    first = offline_window
    path = tmp_path / "workspace.json"
    first.workbench.session.undo.push(
        AddPoint3D(
            first.workbench.session.pairs,
            "oru_1_fixture",
            "pin_tip",
            (1.0, 2.0, 3.0),
            target=first.workbench.session.target,
        )
    )
    assert first.files.save_workspace(path)
    saved = path.read_text()

    wb = Workbench(*simulated_cell())
    second = MainWindow(wb, settings=window_settings(tmp_path, "second"))
    qtbot.addWidget(second)
    shown = []
    second.show_error = shown.append
    try:
        assert not second.files.save_workspace(path)
        assert shown and "is open in videocal (pid" in shown[-1] and "overwrite its work" in shown[-1]
        assert path.read_text() == saved  # nothing written over the first window's work
        assert not second.files.open_workspace(path) and len(shown) == 2
        first.close()  # the first window lets go of the file
        assert second.files.open_workspace(path)
        assert len(wb.session.pairs) == 1 and json.loads(path.read_text())
    finally:
        second.close()
