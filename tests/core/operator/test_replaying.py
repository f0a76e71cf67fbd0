"""The core's replay (``core.replay``) without a window: the bundled sample recording, its frames, joints, pairs and
solve at a position; the first edit branches; closing gives the live session back; a file that is no recording
changes nothing."""

from calib_core.calibration.commands import DeletePair
from calib_core.calibration.commands import AddPoint3D
import hashlib
import shutil
from pathlib import Path

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore
from calib_core.recording.playback import RecordingPlayback
from calib_core.recording.reader import read_recording

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "recordings" / "sample_session.mcap"


@pytest.fixture
def core():
    return OperatorCore(Cell.open())


@pytest.fixture
def recording(tmp_path):
    path = tmp_path / "session.mcap"
    shutil.copy(SAMPLE, path)
    return path


def test_the_recording_as_it_stood_then_and_the_live_session_back_after(core, recording):
    truth = RecordingPlayback(read_recording(recording))
    before = hashlib.sha256(recording.read_bytes()).digest()
    live = core.session.undo.push(
        AddPoint3D(core.session.pairs, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), target=core.session.target)
    ).number
    core.replay.open(recording)
    first = core.replay.seek(0.0)
    assert core.frames.replaying and core.replay.state_text() == "0 pairs, 0 solves so far"
    assert first is not None and np.array_equal(first.image, truth.frames.image(truth.frame_index_at(0.0)))
    assert core.replay.seek(0.0) is None  # the same frame is not handed out twice

    t_mid = (truth._event_times[2] + truth._event_times[3]) / 2
    core.replay.seek(t_mid)
    assert np.allclose(core.joints_deg, truth.joints_at(t_mid))
    assert [p.number for p in core.session.pairs] == [p.number for p in truth.pairs_at(t_mid)]
    assert core.session.result.estimate is None
    core.replay.seek(truth.duration_s)
    assert core.session.result.estimate is not None and core.replay.branched_at_s is None

    branched = []
    core.replay.branched.connect(branched.append)
    core.session.undo.push(
        DeletePair(core.session.pairs, core.session.pairs.pairs()[0].number)
    )  # the operator's first edit
    assert branched == [truth.duration_s] and core.replay.state_text() == f"branched at {truth.duration_s:.1f} s"
    assert core.replay.close() is True  # the branched session stays
    assert not core.frames.replaying and live not in [p.number for p in core.session.pairs]
    assert hashlib.sha256(recording.read_bytes()).digest() == before  # only ever read


def test_closing_an_unbranched_replay_gives_the_live_session_back(core, recording):
    live = core.session.undo.push(
        AddPoint3D(core.session.pairs, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), target=core.session.target)
    ).number
    intrinsics = core.intrinsics
    core.replay.open(recording)
    core.replay.seek(1e9)
    assert core.replay.close() is False
    assert [p.number for p in core.session.pairs] == [live] and core.intrinsics == intrinsics


def test_a_file_that_is_no_recording_is_refused_by_name_and_nothing_changes(core, tmp_path):
    bad = tmp_path / "notes.mcap"
    bad.write_bytes(b"not a recording at all")
    with pytest.raises(FileFormatError, match="notes.mcap"):
        core.replay.open(bad)
    assert core.replay.playback is None and not core.frames.replaying


def test_a_recording_named_live_branched_and_solved_is_no_correction_of_the_live_task(core, tmp_path):
    """The sample recording saved as a file named ``live``: its pairs (picked live when it was made), branched, solved
    again and stored, make a look on a recording, never the live task's correction."""
    from calib_core.calibration.look_place import LookNotAtTask

    path = tmp_path / "live"
    shutil.copy(SAMPLE, path)
    core.replay.open(path)
    truth = RecordingPlayback(read_recording(path))
    core.replay.seek(truth.duration_s)
    assert all(p.view is None or p.view.recorded for p in core.session.pairs)
    core.session.undo.push(DeletePair(core.session.pairs, core.session.pairs.pairs()[0].number))  # branch
    core.picking.calibrate()
    assert core.session.result.context.view_sources  # the recording, by name
    place = core.desk.look_place()
    assert place.at == "recording", place.text
    with pytest.raises(LookNotAtTask):
        core.desk.store_correction()
    assert core.session.corrections.latest(core.task.name) is None
