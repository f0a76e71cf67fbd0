"""``videocal gui`` leaves no controller simulator behind: not after a failed start, not after SIGTERM."""

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from calib_core.workcell import DEFAULT_WORKCELL


@pytest.fixture
def cell_copy(tmp_path):
    """The bundled cell under a unique path, so its simulator can be told from any other."""
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(root / sub, tmp_path / sub)
    return tmp_path / "workcell" / "workcell.yaml"


def _simulators_for(marker: Path) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmdline = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if b"sim-controller" in cmdline and str(marker).encode() in cmdline:
            found.append(int(entry.name))
    return found


def _gui(*args, env=None):
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", **(env or {})}
    return subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", "gui", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


def _wait_gone(marker: Path, timeout_s: float = 10.0) -> list[int]:
    deadline = time.monotonic() + timeout_s
    while (left := _simulators_for(marker)) and time.monotonic() < deadline:
        time.sleep(0.1)
    return left


def test_a_failed_start_stops_the_simulator(cell_copy, tmp_path):
    bad = tmp_path / "hand_eye.yaml"
    bad.write_text("cam2flange: {xyz: [1, 2]}")
    gui = _gui("--workcell", str(cell_copy), "--hand-eye", str(bad))
    out, err = gui.communicate(timeout=120)
    assert gui.returncode == 2, err
    assert "cam2flange.xyz" in err and "must be a list of 3 numbers" in err and "Traceback" not in err
    assert _wait_gone(cell_copy) == []


def test_sigterm_closes_the_window_and_the_simulator(cell_copy, tmp_path):
    shown = tmp_path / "shown.txt"
    gui = _gui("--workcell", str(cell_copy), env={"VIDEOCAL_REPORT_SHOWN": str(shown)})
    try:
        deadline = time.monotonic() + 120
        while not shown.with_suffix(".ready").exists():
            assert gui.poll() is None, gui.stderr.read()
            assert time.monotonic() < deadline, "the window did not come up"
            time.sleep(0.2)
        assert len(_simulators_for(cell_copy)) == 1
        gui.send_signal(signal.SIGTERM)
        gui.wait(timeout=30)
        assert gui.returncode == 0, gui.communicate()[1][-1500:]
        assert _wait_gone(cell_copy) == []
    finally:
        if gui.poll() is None:
            gui.kill()
        gui.communicate()


def test_two_windows_killed_with_sigkill_leave_no_simulator(cell_copy, tmp_path):
    """Two windows on one cell each run their own simulator; kill -9 gives neither window a chance to
    clean up, and still no simulator outlives its window (the child dies with its parent)."""
    guis, ready = [], []
    try:
        for k in range(2):
            shown = tmp_path / f"shown{k}.txt"
            guis.append(_gui("--workcell", str(cell_copy), env={"VIDEOCAL_REPORT_SHOWN": str(shown)}))
            ready.append(shown.with_suffix(".ready"))
        deadline = time.monotonic() + 180
        while not all(r.exists() for r in ready):
            for gui in guis:
                assert gui.poll() is None, gui.stderr.read()
            assert time.monotonic() < deadline, "the windows did not come up"
            time.sleep(0.2)
        sims = _simulators_for(cell_copy)
        assert len(sims) == 2
        for gui in guis:
            gui.send_signal(signal.SIGKILL)
            gui.wait(timeout=30)
        assert _wait_gone(cell_copy) == []
    finally:
        for gui in guis:
            if gui.poll() is None:
                gui.kill()
            gui.communicate()


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "Ctrl+C"])
def test_a_signal_during_start_up_ends_it_and_leaves_no_simulator(cell_copy, tmp_path, signum):
    """A SIGTERM while the cell was loading was ignored for 40 s in one run (no event loop to quit yet), and left the
    simulator running in another; Ctrl+C likewise."""
    shown = tmp_path / "shown.txt"
    gui = _gui("--workcell", str(cell_copy), env={"VIDEOCAL_REPORT_SHOWN": str(shown)})
    try:
        deadline = time.monotonic() + 120
        while not shown.exists():  # the loading window is up; the cell, robot and link load behind it
            assert gui.poll() is None, gui.stderr.read()
            assert time.monotonic() < deadline, "the loading window did not come up"
            time.sleep(0.05)
        gui.send_signal(signum)
        gui.wait(timeout=20)
        if shown.with_suffix(".ready").exists():  # it came up before the signal was handled: closed as Quit does
            assert gui.returncode == 0, gui.stderr.read()[-2000:]
        else:
            assert gui.returncode == 128 + signum, gui.stderr.read()[-2000:]
        assert _wait_gone(cell_copy) == []
    finally:
        if gui.poll() is None:
            gui.kill()
        gui.communicate()


def test_a_relative_workcell_path_opens_the_window(cell_copy, tmp_path):
    """The simulator child ran in the project's folder with the path as given."""
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "gui",
            "--workcell",
            os.path.relpath(cell_copy, tmp_path),
            "--screenshot",
            "shot.png",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=env,
        timeout=180,
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "shot.png").stat().st_size > 10_000
    assert _wait_gone(cell_copy) == []


def test_a_camera_alone_from_the_site_section_opens_a_window_without_a_simulator(cell_copy, tmp_path):
    """A cell with a ``site:`` camera and no controller: the window comes up on the camera, the link
    'not connected', and no simulator is started (``--camera`` no longer needs ``--port``)."""
    import cv2
    import numpy as np

    shots = cell_copy.parent / "shots"
    shots.mkdir()
    cv2.imwrite(str(shots / "a.png"), np.full((48, 64, 3), 90, np.uint8))
    cell_copy.write_text(cell_copy.read_text().replace("\nrobot:", "\nsite:\n  camera: shots\nrobot:", 1))
    png = tmp_path / "window.png"
    gui = _gui("--workcell", str(cell_copy), "--screenshot", str(png))
    started = time.monotonic()
    while gui.poll() is None and time.monotonic() - started < 120:
        assert _simulators_for(cell_copy) == []
        time.sleep(0.2)
    out, err = gui.communicate(timeout=10)
    assert gui.returncode == 0, err
    assert png.stat().st_size > 10_000 and "Traceback" not in err
    gui = _gui("--workcell", str(cell_copy), "--site", "sim", "--camera", str(shots))
    out, err = gui.communicate(timeout=60)
    assert gui.returncode == 2 and "--site sim brings its own controller and camera" in err
