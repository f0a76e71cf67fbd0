"""``videocal render`` writes real PNGs of every view; bad arguments exit 2 with one line."""

import subprocess
import sys

import cv2
import numpy as np
import pytest


def _videocal(*args):
    return subprocess.run([sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=180)


@pytest.mark.parametrize("view", ["virtual", "overview", "true"])
def test_each_view_writes_a_png(tmp_path, view):
    out = tmp_path / f"{view}.png"
    run = _videocal("render", "--location", "oru_1_grasp", "--view", view, "--scale", "0.25", "--out", str(out))
    assert run.returncode == 0, run.stderr
    image = cv2.imread(str(out))
    assert image is not None and image.std() > 10  # a picture, not a blank frame
    if view != "overview":
        assert image.shape[:2] == (240, 320)


def test_home_pose_by_default_and_joints(tmp_path):
    a, b = tmp_path / "home.png", tmp_path / "moved.png"
    assert _videocal("render", "--view", "overview", "--out", str(a)).returncode == 0
    assert _videocal("render", "--view", "overview", "--joints", "40,20,10,0,30,0", "--out", str(b)).returncode == 0
    assert not np.array_equal(cv2.imread(str(a)), cv2.imread(str(b)))


@pytest.mark.parametrize(
    "args, message",
    [
        (["--location", "nowhere"], "no task location 'nowhere'"),
        (["--joints", "1,2,3"], "expected 6 joint values"),
        (["--joints", "a,b,c,d,e,f"], "expected numbers"),
        (["--highlight", "rack_9"], "no component 'rack_9'"),
        (["--workcell", "missing.yaml"], "no such workcell file"),
    ],
)
def test_bad_arguments_exit_2(tmp_path, args, message):
    out = tmp_path / "x.png"
    run = _videocal("render", *args, "--out", str(out))
    assert run.returncode == 2
    assert message in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()
