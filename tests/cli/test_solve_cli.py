"""``videocal solve`` and ``videocal table1`` as a user runs them: a real subprocess, real files."""

import json
import subprocess
import sys

import numpy as np
import pytest

from tests.core.solver.scenes import GRIPPER_CAMERA, pixels, random_points, random_pose


def _videocal(*args):
    return subprocess.run([sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=120)


def _problem(n=6, seed=3):
    rng = np.random.default_rng(seed)
    truth = random_pose(rng)
    P = random_points(rng, n)
    c = GRIPPER_CAMERA
    data = {
        "intrinsics": {
            "fu": c.fu,
            "fv": c.fv,
            "cx": c.cx,
            "cy": c.cy,
            "width": c.width,
            "height": c.height,
            "distortion": list(c.distortion),
        },
        "points_3d": P.tolist(),
        "points_2d": pixels(P, truth, noise_px=0.3, rng=rng).tolist(),
    }
    return truth, data


def test_solve_prints_the_pose_as_json(tmp_path):
    truth, data = _problem()
    data["prior"] = {"R_obj2cam": truth[:3, :3].tolist(), "t_obj2cam_mm": truth[:3, 3].tolist()}
    path = tmp_path / "pairs.json"
    path.write_text(json.dumps(data))
    run = _videocal("solve", str(path))
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["status"] == "ok"
    assert np.linalg.norm(np.array(out["t_obj2cam_mm"]) - truth[:3, 3]) < 3.0
    for key in (
        "R_obj2cam",
        "camera_position_mm",
        "fu",
        "fv",
        "iterations",
        "rms_px",
        "residuals_px",
        "candidates",
        "warnings",
    ):
        assert key in out
    assert set(out["std"]) >= {"t_obj2cam_mm", "rotation_deg", "camera_position_mm"}


def test_failed_solve_exits_3_with_json(tmp_path):
    _, data = _problem()
    data["points_2d"][2] = [data["points_2d"][2][0] + 60.0, data["points_2d"][2][1]]
    path = tmp_path / "pairs.json"
    path.write_text(json.dumps(data))
    run = _videocal("solve", str(path))
    assert run.returncode == 3
    out = json.loads(run.stdout)
    assert out["status"] == "failed" and "point 3" in out["reason"]


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda d: d.pop("points_2d"), "field 'points_2d': required field is missing"),
        (lambda d: d["intrinsics"].pop("fu"), "field 'intrinsics.fu': required field is missing"),
        (lambda d: d.update(colour="red"), "unknown field(s) colour"),
        (lambda d: d.update(points_2d=d["points_2d"][:4]), "6 3D points but 4 2D points"),
        (lambda d: d.update(robust="yes"), "field 'robust': must be a bool"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, mutate, message):
    _, data = _problem()
    mutate(data)
    path = tmp_path / "pairs.json"
    path.write_text(json.dumps(data))
    run = _videocal("solve", str(path))
    assert run.returncode == 2
    assert run.stdout == ""
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], run.stderr


def test_unreadable_files_exit_2(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    for path in (bad, tmp_path / "missing.json"):
        run = _videocal("solve", str(path))
        assert run.returncode == 2 and run.stderr.startswith("error: ") and "Traceback" not in run.stderr


def test_table1_json_in_both_models():
    for model in ("pinhole", "paper"):
        run = _videocal("table1", "--json", "--model", model)
        assert run.returncode == 0, run.stderr
        out = json.loads(run.stdout)
        assert len(out["tests"]) == 10
        assert all(max(abs(v) for v in t["final_error"].values()) < 1e-9 for t in out["tests"])


def test_version_and_help():
    run = _videocal("--version")
    assert run.returncode == 0 and run.stdout.startswith("videocal ")
    run = _videocal("--help")
    assert "solve" in run.stdout and "table1" in run.stdout
