"""Replaying a recording in the real window: the timeline shows the recorded frames, joints, pairs
and results as they were; the first edit branches a new session; the file is never written."""

from calib_core.calibration.commands import AddPoint3D
import hashlib
import shutil
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from tests.app.windows import confirm_move_if_asked
from calib_core.recording.playback import RecordingPlayback
from calib_core.recording.reader import read_recording

SAMPLE = Path(__file__).resolve().parents[2] / "resources" / "recordings" / "sample_session.mcap"
OUTPUT = Path(__file__).resolve().parents[1] / "output"


@pytest.fixture
def window(offline_window):
    return offline_window


@pytest.fixture
def recording(tmp_path):
    path = tmp_path / "session.mcap"
    shutil.copy(SAMPLE, path)
    return path


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_the_timeline_shows_the_recording_as_it_was(qtbot, window, recording):
    win, wb = window, window.workbench
    truth = RecordingPlayback(read_recording(recording))
    live_pair = wb.session.undo.push(
        AddPoint3D(wb.session.pairs, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), target=wb.session.target)
    ).number
    before = _digest(recording)
    win.files.open_recording(recording)
    bar = win.replay
    assert bar.isVisible() and wb.frames.replaying and not win.commands.live.isChecked()
    assert "replaying session.mcap" in win.statusBar().currentMessage()

    # Scrub to the middle of the pick sequence: that frame, those joints, those pairs, no result yet.
    first_solve = truth.solves[0].t_s
    t_mid = (truth._event_times[2] + truth._event_times[3]) / 2
    bar.slider.setValue(int(t_mid * 1000))  # the slider has millisecond steps
    t_mid = bar.position_s
    k = truth.frame_index_at(t_mid)
    assert np.array_equal(win.camera.last_frame.image, truth.frames.image(k))
    assert np.allclose(wb.joints_deg, truth.joints_at(t_mid))
    assert [p.number for p in wb.session.pairs] == [p.number for p in truth.pairs_at(t_mid)] and len(
        wb.session.pairs
    ) >= 1
    assert wb.session.result.estimate is None and t_mid < first_solve

    # After the solves: the last result appears, re-solved from its recorded inputs exactly.
    bar.seek(truth.duration_s)
    result = wb.session.result.estimate
    assert result is not None and win.commands.calibrate.isEnabled()
    assert np.array_equal(result.solution.to_dict()["t_obj2cam_mm"], truth.solves[-1].result["t_obj2cam_mm"])
    assert "OK" in win.results.verdict.text() and "mm" in win.results.details.text()

    # Back before the first pick: no pairs, no result.
    bar.seek(0.0)
    assert len(wb.session.pairs) == 0 and wb.session.result.estimate is None

    # The robot is not moved while the views show a recording.
    qtbot.mouseClick(win.commands.go_task, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    assert "close the replay before moving the robot" in win.results.status.text()

    # Play runs the clock forward.
    bar.play()
    qtbot.waitUntil(lambda: bar.position_s > 0.5, timeout=5_000)
    bar.pause()
    assert not bar.playing

    # Closing without an edit gives the live session back, pair and all.
    qtbot.mouseClick(bar.close_button, Qt.MouseButton.LeftButton)
    assert not bar.isVisible() and not wb.frames.replaying and win.commands.live.isChecked()
    assert [p.number for p in wb.session.pairs] == [live_pair]
    assert _digest(recording) == before


def test_an_edit_branches_a_new_session_and_leaves_the_file_alone(qtbot, window, recording):
    win, wb = window, window.workbench
    truth = RecordingPlayback(read_recording(recording))
    before = _digest(recording)
    win.files.open_recording(recording)
    bar = win.replay
    bar.seek(truth.duration_s)
    n = len(wb.session.pairs)
    # The operator deletes a pair through the table and re-solves on the recorded frame.
    win.table.selectRow(0)
    qtbot.mouseClick(win.commands.delete, Qt.MouseButton.LeftButton)
    assert len(wb.session.pairs) == n - 1
    assert bar.branched_at_s == pytest.approx(truth.duration_s) and "branched" in bar.state_label.text()
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    assert wb.session.result.estimate is not None and wb.session.result.estimate.solution.rms_px < 2.0
    # Scrubbing moves the frames but no longer the branched pairs.
    bar.seek(0.0)
    assert len(wb.session.pairs) == n - 1 and win.camera.last_frame.index == 0
    qtbot.mouseClick(bar.close_button, Qt.MouseButton.LeftButton)
    assert len(wb.session.pairs) == n - 1  # the branch stays open
    assert _digest(recording) == before


def test_bad_and_cut_off_recordings(qtbot, window, tmp_path, recording):
    win, wb = window, window.workbench
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a recording")
    win.files.open_recording(junk)
    assert "not an MCAP recording" in win.results.status.text() and "junk.mcap" in win.results.status.text()
    assert not win.replay.isVisible() and not wb.frames.replaying
    # A recording cut off by a crash opens with what it holds and offers recovery.
    data = recording.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) * 2 // 3])
    win.files.open_recording(cut)
    assert win.replay.isVisible() and not win.replay.recover_button.isHidden()
    qtbot.mouseClick(win.replay.recover_button, Qt.MouseButton.LeftButton)
    recovered = read_recording(tmp_path / "cut-recovered.mcap")
    assert recovered.complete and len(recovered.messages) == len(read_recording(cut).messages)


def test_replay_screenshot(qtbot, window, recording):
    win = window
    win.files.open_recording(recording)
    win.replay.seek(win.replay.playback.duration_s)
    qtbot.waitUntil(win.virtual.is_current, timeout=10_000)
    qtbot.wait(200)
    OUTPUT.mkdir(exist_ok=True)
    image = win.grab()
    image.save(str(OUTPUT / "window_replay.png"))
    # The bar sits on top of the panes and the recorded frame fills the camera pane.
    bar_pos = win.replay.mapTo(win, QPoint(0, 0))
    cam_pos = win.camera.mapTo(win, QPoint(0, 0))
    assert bar_pos.y() < cam_pos.y()
    frame = win.camera.last_frame.image
    assert frame.shape == (960, 1280, 3) and frame.std() > 10


def test_a_recording_from_another_camera_mode_replays_with_its_own_intrinsics(qtbot, window, tmp_path):
    """A session recorded at 640 x 480 opens in a window whose camera gives 1280 x 960: picks and solves on
    its frames use the recorded intrinsics, and closing the replay gives the live ones back."""
    from calib_core.recording.recorder import SessionRecorder

    win, wb = window, window.workbench
    live = wb.intrinsics
    half = live.scaled(0.5)
    path = tmp_path / "half.mcap"
    image = np.zeros((half.height, half.width, 3), np.uint8) + 90
    with SessionRecorder(path, drop_when_busy=False) as rec:
        rec.record_setup(intrinsics=half.to_dict())
        for k in range(3):
            rec.record_frame(image, k / 15)
            rec.record_joints(k, 20 * k, k / 15, list(wb.joints_deg))
    win.files.open_recording(path)
    from app.gui.virtual_pane import RENDER_SCALE

    assert wb.intrinsics == half
    assert win.virtual.intrinsics == half.without_distortion().scaled(RENDER_SCALE)  # the virtual camera follows
    assert win.camera.last_frame.image.shape[:2] == (half.height, half.width)
    win.replay.close_replay()
    assert wb.intrinsics == live and win.virtual.intrinsics == live.without_distortion().scaled(RENDER_SCALE)


def test_a_branchs_new_pair_is_numbered_after_the_recorded_ones_and_undo_stays_in_the_branch(qtbot, window, recording):
    """A new pair took number 1 beside recorded pair 1; the camera click meant for it moved the
    recorded pair, Undo twice deleted the recorded pair and Redo left two rows numbered 1."""
    win, wb = window, window.workbench
    win.files.open_recording(recording)
    win.replay.seek(win.replay.playback.duration_s)
    recorded = wb.session.pairs.pairs()
    assert recorded and min(p.number for p in recorded) == 1
    fixture = wb.workcell.component("oru_1_fixture")
    number = wb.picking.pick_model_point("oru_1_fixture", "pin_tip", tuple(fixture.item2world[:3, 3]))
    assert win.replay.branched_at_s is not None
    assert number == max(p.number for p in recorded) + 1
    win.camera.subpixel.setChecked(False)
    qtbot.mouseClick(win.camera.view, Qt.MouseButton.LeftButton, pos=QPoint(300, 200))
    assert wb.session.pairs.get(number).pixel is not None
    assert [p for p in wb.session.pairs if p.number != number] == recorded  # no recorded pair moved
    wb.undo()
    wb.undo()
    assert wb.session.pairs.pairs() == recorded  # undo took back the branch's edits only
    assert wb.undo() is None and wb.session.pairs.pairs() == recorded  # and reaches no further
    wb.redo()
    numbers = [p.number for p in wb.session.pairs]
    assert len(numbers) == len(set(numbers)) == len(recorded) + 1


def test_a_look_from_the_recording_is_never_stored_as_the_task_s_correction_by_itself(qtbot, window, recording):
    """Open a recording, seek past its recorded solve (made live at the task), Store correction: the window asks,
    naming the recording, and Cancel stores nothing. The same after branching (a pair deleted, Calibrate again):
    the remaining pairs still come from the recording."""
    from tests.app.windows import answer_questions

    win, wb = window, window.workbench
    truth = RecordingPlayback(read_recording(recording))
    win.files.open_recording(recording)
    bar = win.replay
    bar.seek(truth.duration_s)
    assert wb.session.result.estimate is not None
    assert all(p.view is None or p.view.source == "session.mcap" for p in wb.session.pairs)
    asked = answer_questions(qtbot, ["Cancel"])
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    assert asked and "recording session.mcap" in asked[0], asked
    assert wb.session.corrections.history(wb.task.name) == []
    win.table.selectRow(0)
    qtbot.mouseClick(win.commands.delete, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    assert bar.branched_at_s is not None and wb.session.result.estimate is not None
    asked = answer_questions(qtbot, ["Cancel"])
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    assert asked and "recording session.mcap" in asked[0], asked
    assert wb.session.corrections.history(wb.task.name) == []
