"""Another cell in the window: File > Open cell starts that cell's simulator and shows its robot; a bad cell
changes nothing; a workspace of another cell is refused before anything changes; a bug is logged, not shown raw."""

import numpy as np
import pytest

from app.gui.error_boundary import internal_error_log
from calib_core.workcell import DEFAULT_WORKCELL
from calib_core.workcell.starter import write_starter_cell
from tests.app.windows import pick_pair, wait_for_settled_frame
from tests.vendor_robots import SHARE, UR5, require


@pytest.fixture(scope="module")
def ur5_cell(tmp_path_factory):
    return write_starter_cell(tmp_path_factory.mktemp("ur5") / "cell", require(UR5), [SHARE]).workcell_path


def test_open_cell_replaces_the_window_with_the_cells_robot_and_simulator(qtbot, launcher, ur5_cell, tmp_path):
    win = launcher.open(DEFAULT_WORKCELL)
    qtbot.addWidget(win)
    win.show()
    old = win.workbench
    qtbot.waitUntil(lambda: old.link_up, timeout=15_000)
    # A file that is not a cell: an error, and the window and its simulator go on.
    bad = tmp_path / "bad.yaml"
    bad.write_text("schema_version: 2\nunits: {length: mm, angle: deg}\nrobot: {urdf: nothing.urdf}\ncomponents: []\n")
    assert not win.files.open_cell(str(bad))
    assert "robot.urdf" in win.results.status.text() and win.isVisible() and old.site.process.running
    # The UR5 cell: a new window with its robot, and the old simulator stops.
    assert win.files.open_cell(str(ur5_cell))
    new = next(w for w in _shown_windows() if w is not win)
    qtbot.addWidget(new)
    try:
        assert not win.isVisible() and not old.site.process.running
        wb = new.workbench
        assert wb.robot.joint_names[0] == "shoulder_pan_joint" and wb.cell.name == "ur5_robot cell"
        qtbot.waitUntil(lambda: wb.link_up, timeout=15_000)
        assert np.allclose(wb.joints_deg, wb.cell.home_joints, atol=1e-3)  # the UR5's simulator, at its home
        assert new.files.recent_cells.paths()[0] == str(ur5_cell.resolve())
    finally:
        new.close()
    assert not wb.site.process.running


def _shown_windows():
    from PySide6.QtWidgets import QApplication

    from app.gui.main_window import MainWindow

    return [w for w in QApplication.topLevelWidgets() if isinstance(w, MainWindow) and w.isVisible()]


def test_a_workspace_of_another_cell_is_refused_and_nothing_changes(qtbot, launcher, ur5_cell, tmp_path):
    bundled = launcher.open(DEFAULT_WORKCELL)
    qtbot.addWidget(bundled)
    wb = bundled.workbench
    fixture = wb.workcell.component("oru_1_fixture")
    wait_for_settled_frame(qtbot, bundled)
    pick_pair(wb, "oru_1_fixture", "pin_tip", fixture.item2world[:3, 3], (100.0, 100.0))
    path = tmp_path / "bundled_workspace.json"
    assert bundled.files.save_workspace(path)
    bundled.close()
    ur5 = launcher.open(ur5_cell)
    qtbot.addWidget(ur5)
    try:
        tasks_before = dict(ur5.workbench.workcell.task_locations)
        assert not ur5.files.open_workspace(path)
        text = ur5.results.status.text()
        assert "belongs to the cell 'space station robotic test bed'" in text and "ur5_robot cell" in text
        assert ur5.workbench.workcell.task_locations == tasks_before and len(ur5.workbench.session.pairs) == 0
    finally:
        ur5.close()


def test_a_bug_is_logged_with_its_traceback_and_named_to_the_operator(qtbot, launcher):
    win = launcher.open(DEFAULT_WORKCELL)
    qtbot.addWidget(win)
    try:

        def broken():
            return {}["no such key"]

        win.report(broken)()
        log = internal_error_log()
        assert "internal error (KeyError" in win.results.status.text() and str(log) in win.results.status.text()
        assert "Traceback" in log.read_text() and "broken" in log.read_text()
        # A user's mistake is shown as it is, and logs nothing.
        size = log.stat().st_size
        win.report(win.workbench.set_task)("nowhere")
        assert win.results.status.text().count("no task location 'nowhere'") == 1
        assert log.stat().st_size == size
    finally:
        win.close()


def test_a_failed_save_is_neither_recent_nor_saved(qtbot, launcher, tmp_path):
    win = launcher.open(DEFAULT_WORKCELL)
    qtbot.addWidget(win)
    try:
        wb, autosave = win.workbench, win.files.autosave
        assert not autosave.save_now()  # nothing changed: nothing written
        wb.picking.pick_model_point(
            "oru_1_fixture", "pin_tip", wb.workcell.component("oru_1_fixture").item2world[:3, 3]
        )
        target = tmp_path / "no such folder" / "workspace.json"
        assert not win.files.save_workspace(target)
        assert str(target) not in win.files.recent.paths() and "no such folder" in win.results.status.text()
        assert autosave.save_now() and autosave.path.is_file()  # the work is still unsaved: the autosave keeps it
        assert win.files.save_workspace(tmp_path / "workspace.json")
        assert win.files.recent.paths()[0] == str(tmp_path / "workspace.json")
        assert not autosave.path.exists() and not autosave.save_now()  # saved: nothing left to recover
    finally:
        win.close()


def test_each_window_autosaves_alone_and_an_unsaved_session_is_offered_once(qtbot, launcher, tmp_path):
    launcher.settings.setValue("files/autosave_dir", str(tmp_path))
    first, second = launcher.open(DEFAULT_WORKCELL), launcher.open(DEFAULT_WORKCELL)
    for win in (first, second):
        qtbot.addWidget(win)
    fixture = first.workbench.workcell.component("oru_1_fixture")
    for win, feature in ((first, "pin_tip"), (second, "plate_top_left")):
        win.workbench.picking.pick_model_point("oru_1_fixture", feature, fixture.item2world[:3, 3])
        assert win.files.autosave.save_now()
    assert (
        first.files.autosave.path != second.files.autosave.path
        and len(list((tmp_path / "recovery").glob("autosave-*.json"))) == 2
    )
    assert first.files.autosave.orphans() == []  # the other window is alive: its file is not an orphan
    # The first window quits with unsaved work (and, as a crash would, from another process id).
    first.close()
    orphan = first.files.autosave.path
    crashed = orphan.with_name(f"autosave-{_dead_pid()}-1.json")
    orphan.replace(crashed)
    second.close()  # saved nothing either: it leaves its own file too
    third = launcher.open(DEFAULT_WORKCELL)
    qtbot.addWidget(third)
    try:
        offered = third.files.autosave.orphans()
        assert crashed in offered and len(third.files.restore_actions) == len(offered)
        assert third.files.restore_autosave(crashed)
        assert [p.feature for p in third.workbench.session.pairs] == ["pin_tip"]
        assert crashed not in third.files.autosave.orphans() and str(crashed) not in third.files.restore_actions
    finally:
        third.close()


def _dead_pid() -> int:
    """The process id of a process that has ended (as a crashed window's)."""
    import subprocess

    p = subprocess.Popen(["true"])
    p.wait()
    return p.pid
