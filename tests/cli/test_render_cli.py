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


def test_at_task_renders_from_the_task_pose_itself(tmp_path):
    """``--location`` shows the approach; the first look is made at the task location itself (a cell
    whose approach render looked fine failed its first look there). ``--at-task`` shows that view."""
    from calib_core.workcell import load_workcell

    a, t = tmp_path / "approach.png", tmp_path / "task.png"
    run_a = _videocal("render", "--location", "oru_1_grasp", "--scale", "0.25", "--out", str(a))
    run_t = _videocal("render", "--at-task", "oru_1_grasp", "--scale", "0.25", "--out", str(t))
    assert run_a.returncode == 0 and run_t.returncode == 0, run_t.stderr
    joints = [
        np.array([float(v) for v in r.stdout.split("joints ")[1].split(" deg")[0].split(", ")]) for r in (run_a, run_t)
    ]
    cell = load_workcell()
    robot = cell.load_robot()
    task = cell.task("oru_1_grasp")
    np.testing.assert_allclose(
        robot.fk(joints[1], "tcp")[:3, 3], task.tcp2base[:3, 3], atol=0.5
    )  # (joints printed to 0.01 deg)
    np.testing.assert_allclose(robot.fk(joints[0], "tcp")[:3, 3], task.approach2base[:3, 3], atol=0.5)
    assert np.abs(cv2.imread(str(a)).astype(int) - cv2.imread(str(t)).astype(int)).mean() > 5.0  # another view
    both = _videocal("render", "--location", "oru_1_grasp", "--at-task", "oru_1_grasp", "--out", str(t))
    assert both.returncode == 2 and "not allowed with" in both.stderr
