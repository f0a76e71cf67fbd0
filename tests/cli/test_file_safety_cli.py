"""Commands that write next to the user's files replace nothing they should not: `recover --out` puts a
whole copy in place (a complete file) and `sim-controller --link` refuses a path that holds a file."""

import subprocess
import sys

from calib_core.recording.reader import read_recording
from calib_core.recording.recorder import SessionRecorder


def _videocal(*args, timeout=60):
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=timeout
    )


def test_recover_writes_a_whole_file_over_an_existing_one(tmp_path):
    cut = tmp_path / "cut.mcap"
    rec = SessionRecorder(cut, frames="jpeg")
    for k in range(50):
        rec.record_joints(k, 20 * k, 0.02 * k, [0.0] * 6)
        if k in (24, 49):
            assert rec.flush()  # two closed chunks, as a crash would leave them
    data = cut.read_bytes()
    rec.close()
    cut.write_bytes(data[: len(data) * 2 // 3])  # killed mid-write: no footer
    out = tmp_path / "out.mcap"
    out.write_bytes(b"an older recovered file")
    run = _videocal("recover", str(cut), "--out", str(out))
    assert run.returncode == 0, run.stderr
    back = read_recording(out)
    assert back.complete and len(back.messages) > 10
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary file left


def test_sim_controller_does_not_replace_a_file_with_its_link(tmp_path):
    precious = tmp_path / "notes.txt"
    precious.write_text("keep me")
    run = _videocal("sim-controller", "--pty", "--link", str(precious), timeout=30)
    assert (
        run.returncode == 2 and "error:" in run.stderr and "not a link" in run.stderr and "Traceback" not in run.stderr
    )
    assert precious.read_text() == "keep me"
