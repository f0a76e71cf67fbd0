"""Recording in the real window when the disk fails: REC goes off, the operator is told why and
offered to record on as JPEG; and a valid recording without joint samples opens for replay."""

import os

import numpy as np

from calib_core.recording.reader import read_recording
from calib_core.recording.recorder import SessionRecorder
from calib_core.recording.schemas import FRAME_TOPIC
from tests.app.windows import answer_next_question


def test_a_full_disk_stops_rec_and_the_operator_records_on_as_jpeg(qtbot, window, tmp_path):
    win = window
    full = tmp_path / "session.mcap"
    os.symlink("/dev/full", full)  # every write to it fails with ENOSPC, as on a full disk
    win.files.start_recording(full)
    assert win.files.record_action.isChecked()
    answered = answer_next_question(qtbot, "Record as JPEG")
    qtbot.waitUntil(lambda: bool(answered), timeout=20_000)
    assert "No space left on device" in answered[0] and "session-jpeg.mcap" in answered[0]
    assert "No space left on device" in win.results.status.text()
    again = tmp_path / "session-jpeg.mcap"
    qtbot.waitUntil(
        lambda: win.workbench.recording.recorder is not None and win.workbench.recording.recorder.path == again,
        timeout=5_000,
    )
    assert win.files.record_action.isChecked() and win.workbench.recording.recorder.frames == "jpeg"
    qtbot.waitUntil(
        lambda: win.workbench.recording.recorder.messages > 0 and win.workbench.recording.recorder.frames_written > 0,
        timeout=20_000,
    )
    win.files.stop_recording()
    assert win.workbench.recording.recorder is None and not win.files.record_action.isChecked()
    contents = read_recording(again)
    assert contents.complete and contents.topic(FRAME_TOPIC)


def test_declining_leaves_rec_off_and_the_window_working(qtbot, window, tmp_path):
    win = window
    full = tmp_path / "session.mcap"
    os.symlink("/dev/full", full)
    win.files.start_recording(full)
    answered = answer_next_question(qtbot, "Cancel")
    qtbot.waitUntil(lambda: bool(answered), timeout=20_000)
    assert win.workbench.recording.recorder is None and not win.files.record_action.isChecked()
    win.status_line.update()
    assert win.status_line.record_label.text() == ""  # no REC lit for a recorder that stopped


def test_a_recording_without_joint_samples_replays(qtbot, window, tmp_path):
    win = window
    path = tmp_path / "frames_only.mcap"
    with SessionRecorder(path, drop_when_busy=False) as rec:
        rec.record_setup(note="a camera, no robot")
        for k in range(20):
            image = np.zeros((240, 320, 3), np.uint8) + np.uint8(10 * k)
            rec.record_frame(image, rec.clock() - 2.0 + k / 10)
    win.files.open_recording(path)
    assert win.replay.playback is not None and len(win.replay.playback.frames) == 20
    assert "error" not in win.results.status.text().lower()
