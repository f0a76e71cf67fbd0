"""``scripts/make_sample_recording.py``, which makes the bundled sample recording the replay tests and the docs use,
run as its maintainer runs it (from another folder, into a file of the test's): a whole session in simulated time, at
the rates it states, with the looks and the stored correction the replay finds in the bundled one."""

import subprocess
import sys
from pathlib import Path

import numpy as np

from calib_core.recording.playback import RecordingPlayback
from calib_core.recording.reader import read_recording

SCRIPT = Path(__file__).resolve().parents[3] / "scripts" / "make_sample_recording.py"


def test_the_script_records_a_whole_session_at_its_stated_rates(tmp_path):
    out = tmp_path / "made" / "sample.mcap"
    run = subprocess.run(
        [sys.executable, str(SCRIPT), "--out", str(out)], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert out.is_file() and not (out.parent / "sample.part.mcap").exists()  # the part renamed, whole
    contents = read_recording(out)
    assert contents.complete, contents.problem
    playback = RecordingPlayback(contents)
    # 50 Hz joints and 15 fps frames on the simulated clock, whatever this machine's speed
    assert np.isclose(np.median(np.diff(playback.joint_times_s)), 0.02, atol=1e-4)
    assert np.isclose(np.median(np.diff(playback.frames.times_s)), 1 / 15, atol=1e-3) and len(playback.frames) > 100
    # six pairs picked, solved plainly then robustly, both ok; the correction stored
    assert len(playback.pairs_at(playback.duration_s)) == 6
    assert [s.inputs.get("robust") for s in playback.solves] == [False, True]
    assert all(s.result.get("status") == "ok" for s in playback.solves)
    assert contents.topic("/videocal/corrections")
    assert "wrote" in run.stdout and str(out) in run.stdout
