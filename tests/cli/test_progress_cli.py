"""Long commands show their progress on a terminal (counts, rate, time left), and nothing of it where their output is
read by a program: with --json, or with standard error not a terminal."""

from __future__ import annotations

import re
import subprocess
import sys

from tests.terminal_run import run_on_terminal


def test_calibrate_hand_eye_shows_its_progress_on_a_terminal_and_not_with_json(tmp_path):
    from calib_core.camera.intrinsics_io import save_intrinsics
    from tests.app.recorded_sets import recorded_set
    from videocal_sim.test_bed import TestBed

    poses = recorded_set(tmp_path / "set", moved_view=3, moved_mm=0.0)
    save_intrinsics(tmp_path / "camera.yaml", TestBed.create().intrinsics)
    args = ["calibrate-hand-eye", str(poses), "--intrinsics", str(tmp_path / "camera.yaml")]
    args += ["--out", str(tmp_path / "mount.yaml")]
    code, out, terminal = run_on_terminal(args)
    assert code == 0, terminal
    # the bar, with its counts and the time left ("3/10 [00:00<00:01, ...")
    assert "finding the board" in terminal and re.search(r"\d+/10 \[\d\d:\d\d<\d\d:\d\d", terminal), terminal
    assert "finding the board" not in out
    code, out, terminal = run_on_terminal([*args, "--json"])
    assert code == 0 and "finding the board" not in terminal and "finding the board" not in out
    import json

    assert json.loads(out)["rms_px"] > 0  # the JSON whole, nothing of a bar in it
    piped = subprocess.run(
        [sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=300
    )  # a log or a script: no bar
    assert piped.returncode == 0 and "finding the board" not in piped.stderr
