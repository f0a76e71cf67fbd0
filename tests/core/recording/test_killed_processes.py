"""Real crashes: a recording process and a saving process killed with SIGKILL at an arbitrary moment.

A killed recorder leaves a file that holds every message it had reported written (it counts
what is in chunks handed to the OS) and all but the last second, and ``recover`` makes it whole. A process killed while
saving a workspace leaves the old file or the new one,
always loadable, never half of either.
"""

import os
import signal
import sys
import textwrap
import time

import pytest

from calib_core.recording.frame_track import FrameTrack
from calib_core.recording.reader import read_recording, recover
from calib_core.recording.schemas import JOINTS_TOPIC, VIDEO_TOPIC
from calib_core.workspace.workspace import load_workspace
from tests.core.recording.recorder_process import RECORDER, read_until, start

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="SIGKILL")


SAVER = textwrap.dedent(
    """
    import sys
    from calib_core.calibration.correspondences import Correspondence
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.calibration.corrections import CorrectionTable
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import Workspace, save_workspace
    cell = load_workcell()
    intr = load_intrinsics(cell.intrinsics_path)
    k = 0
    while True:
        n = 200 + (k % 2) * 300  # two different sizes, so old and new files differ
        pairs = [Correspondence(i + 1, "oru_1_fixture", None, (float(i), 2.0, 3.0), (10.0 + i, 20.0)) for i in range(n)]
        ws = Workspace(str(cell.path), intr, dict(cell.task_locations), "oru_1_fixture", pairs, CorrectionTable())
        save_workspace(sys.argv[1], ws)
        k += 1
        print(k, n, flush=True)
    """
)


def test_a_recorder_killed_mid_recording_keeps_every_reported_message(tmp_path):
    path = tmp_path / "killed.mcap"
    proc = start(RECORDER, path)
    last = read_until(proc, lambda line: int(line.split()[1]) >= 45)  # past a keyframe interval
    killed_at_ns = time.time_ns()
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(10)
    proc.stdout.close()
    proc.stderr.close()
    reported_messages, reported_frames = map(int, last.split())
    contents = read_recording(path)
    assert not contents.complete and contents.problem
    assert len(contents.messages) >= reported_messages
    # the file is chunked: what the kill lost is the chunk in progress, at most the last second
    assert max(m.log_time_ns for m in contents.messages) >= killed_at_ns - 1_000_000_000
    assert len(contents.topic(VIDEO_TOPIC)) >= reported_frames and len(contents.topic(JOINTS_TOPIC)) >= 3 * (
        reported_frames - 1
    )
    fixed = tmp_path / "fixed.mcap"
    recover(path, fixed)
    again = read_recording(fixed)
    assert again.complete and [m.raw for m in again.messages] == [m.raw for m in contents.messages]
    track = FrameTrack(again)
    k = reported_frames - 1
    image = track.image(k)
    # the red block of frame k is where the recorder drew it
    x0 = (k * 3) % 280
    assert image[120, x0 + 5 : x0 + 35, 0].mean() > 180 and image[60, x0 + 5 : x0 + 35, 0].mean() < 180


def test_a_process_killed_while_saving_leaves_a_whole_workspace(tmp_path):
    path = tmp_path / "w.json"
    for attempt in range(4):
        proc = start(SAVER, path)
        read_until(proc, lambda line: int(line.split()[0]) >= 2 + attempt)
        time.sleep(0.003 * attempt)  # land the kill at different points of a save
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
        ws = load_workspace(path)  # raises on a half-written file
        assert len(ws.pairs) in (200, 500) and ws.pairs[-1].number == len(ws.pairs)
