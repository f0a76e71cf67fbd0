"""The operator's files through the real window: recent workspaces, a recording and a workspace saved while
calibrating, an unsaved session offered from its autosave."""

from calib_core.calibration.commands import ClearPairs
from calib_core.calibration.commands import AddPoint3D
from PySide6.QtCore import QSettings, Qt

from app.gui.main_window import MainWindow
from app.gui.workbench import Workbench
from tests.app.windows import answer_file_dialog, wait_for_settled_frame
from videocal_sim.sim_site import simulated_cell


def test_recent_files_reopen_a_workspace(qtbot, window, tmp_path):
    win, wb = window, window.workbench
    wb.session.undo.push(
        AddPoint3D(wb.session.pairs, "oru_1_fixture", "pin_tip", (1127.5, -421.8, 1367.7), target=wb.session.target)
    )
    win.files.save_workspace(tmp_path / "w.json")
    wb.session.undo.push(ClearPairs(wb.session.pairs))
    win.files.recent.fill()
    actions = [a for a in win.files.recent.menu.actions() if a.text() == str(tmp_path / "w.json")]
    assert actions
    actions[0].trigger()
    assert len(wb.session.pairs) == 1


def test_workspace_and_recording_from_the_window(qtbot, window, tmp_path):
    from calib_core.recording.reader import read_recording
    from calib_core.recording.schemas import EVENT_TOPIC, JOINTS_TOPIC, VIDEO_TOPIC

    win = window
    wb = win.workbench
    win.files.start_recording(tmp_path / "session.mcap")
    assert win.files.record_action.isChecked()
    wait_for_settled_frame(qtbot, win)  # a pick holds the newest frame: one taken with the robot settled
    wb.picking.pick_model_point("oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0))
    wb.picking.pick_image_point((100.0, 120.0))
    qtbot.keyClick(win, Qt.Key.Key_Return, Qt.KeyboardModifier.ControlModifier)  # Accept
    qtbot.waitUntil(lambda: wb.recording.recorder.messages > 20, timeout=10_000)  # frames and joints flow in

    def recording_shown() -> bool:  # the status line the window's timer refreshes
        win._update_status()
        return "REC" in win.status_line.record_label.text()

    qtbot.waitUntil(recording_shown, timeout=10_000)
    win.files.save_workspace(tmp_path / "w.json")
    win.files.stop_recording()
    contents = read_recording(tmp_path / "session.mcap")
    assert contents.complete and contents.topic(VIDEO_TOPIC) and contents.topic(JOINTS_TOPIC)
    # (link_state events may come and go with the controller; the operator's edits are these)
    assert [m.payload["kind"] for m in contents.topic(EVENT_TOPIC) if m.payload["kind"].startswith("pair_")] == [
        "pair_added",
        "pair_changed",
        "pair_accepted",
    ]
    # Clear, then open the saved workspace: the pair comes back.
    wb.session.undo.push(ClearPairs(wb.session.pairs))
    assert len(wb.session.pairs) == 0
    win.files.open_workspace(tmp_path / "w.json")
    assert [p.feature for p in wb.session.pairs] == ["pin_tip"] and win.table.rowCount() == 1
    # A bad file is a message; nothing is lost.
    (tmp_path / "bad.json").write_text("{broken")
    win.files.open_workspace(tmp_path / "bad.json")
    assert "not valid JSON" in win.results.status.text()
    assert len(wb.session.pairs) == 1


def test_an_unsaved_session_is_offered_from_its_autosave(qtbot, tmp_path):
    from calib_core.calibration.correspondences import Correspondence
    from calib_core.workspace.workspace import Workspace, save_workspace

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
    settings.setValue("files/autosave_dir", str(tmp_path))
    settings.setValue("window/ask_unsaved", False)
    cell, site = simulated_cell()
    (tmp_path / "recovery").mkdir()
    save_workspace(
        tmp_path / "recovery" / "autosave.json",
        Workspace(
            "cell",
            cell.intrinsics,
            {},
            "oru_1_fixture",
            [Correspondence(1, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), (10.0, 20.0))],
            cell=cell.identity.to_dict(),
        ),
    )
    wb = Workbench(cell, site)
    win = MainWindow(wb, settings=settings)
    qtbot.addWidget(win)
    try:
        assert "Restore" in win.files.restore_action.text()
        win.files.restore_action.trigger()
        assert [p.feature for p in wb.session.pairs] == ["pin_tip"]
        # Save after a restore wrote into the recovery folder without a dialog, and the next
        # start offered that file again. A restored session has no file yet: Save asks where.
        assert win.files.workspace_path is None
        chosen = tmp_path / "mine.json"
        asked = answer_file_dialog(chosen)
        assert win.files.save_workspace_dialog()
        assert asked == ["Save workspace"] and chosen.is_file()
        assert sorted(p.name for p in (tmp_path / "recovery").iterdir()) == ["recovered-autosave.json"]
        assert win.files.autosave.orphans() == []
        assert not win.files.save_workspace(
            tmp_path / "recovery" / "w.json"
        )  # the recovery folder holds autosaves only
        assert "recovery folder" in win.results.status.text() and not (tmp_path / "recovery" / "w.json").exists()
    finally:
        win.close()


def test_a_folder_that_cannot_be_written_is_one_line_naming_it(qtbot, window, tmp_path):
    """Save workspace and Record session, each into a folder the system refuses (here a file where the folder should
    be: as root a read-only folder refuses nothing), say so naming the file, not "internal error", and leave no file
    and no recorder behind."""
    win, wb = window, window.workbench
    blocked = tmp_path / "not-a-folder"
    blocked.write_text("a file")
    asked = answer_file_dialog(blocked / "w.json")
    assert not win.files.save_workspace_dialog(ask_path=True)
    shown = win.results.status.text()
    assert asked == ["Save workspace"] and str(blocked / "w.json") in shown, shown
    assert "internal error" not in shown and "Not a directory" in shown
    assert win.files.workspace_path is None

    asked = answer_file_dialog(blocked / "session.mcap")
    win.files.record_action.trigger()
    qtbot.waitUntil(lambda: asked == ["Record session"] and not win.files.record_action.isChecked())
    shown = win.results.status.text()
    assert str(blocked / "session.mcap") in shown and "internal error" not in shown, shown
    assert wb.recording.recorder is None and blocked.read_text() == "a file"
