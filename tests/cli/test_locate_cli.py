"""``videocal locate`` as a user runs it (a real subprocess, real files): a known object's pose in one photo.

On a photograph nobody on the team took (OpenCV's real-time pose tutorial: a cookie box on a wooden table,
its mesh ``box.ply`` in cm, the tutorial's nominal 45 mm lens on a 22.3 x 14.9 mm sensor at 718 x 480 px) and
on the simulated camera, where the truth scores it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import save_intrinsics
from tests.core.look.box_photo import BOX, HAND_PRIOR, PHOTO, TUTORIAL_CAMERA


def _videocal(*args, cwd=None):
    env_cwd = cwd or Path.cwd()
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=env_cwd,
        env={**__import__("os").environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])},
    )


def _locate_box(photos: list[str], intrinsics: str, prior: str, *more: str):
    """``videocal locate`` of the tutorial's box (its mesh in cm) in ``photos``."""
    return _videocal(
        "locate", *photos, "--mesh", str(BOX), "--units", "cm", "--intrinsics", intrinsics, "--prior", prior, *more
    )


@pytest.fixture(scope="module")
def photo_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("locate")
    save_intrinsics(folder / "camera.yaml", TUTORIAL_CAMERA)
    return folder


def _prior(folder: Path, name: str, pose: dict) -> Path:
    path = folder / name
    path.write_text(json.dumps(pose))
    return path


def _moved(pose: dict, mm: float, deg: float, rng) -> dict:
    d = rng.normal(size=3)
    R = Rotation.from_rotvec(
        np.radians(deg) * Rotation.random(random_state=int(rng.integers(1 << 30))).as_rotvec() / np.pi
    ).as_matrix() @ np.array(pose["R_obj2cam"])
    return {
        "R_obj2cam": R.tolist(),
        "t_obj2cam_mm": (np.array(pose["t_obj2cam_mm"]) + mm * d / np.linalg.norm(d)).tolist(),
    }


def test_the_tutorial_box_is_located_by_its_edges_and_its_corners_agree(photo_files):
    overlay = photo_files / "located.png"
    run = _locate_box(
        [str(PHOTO)],
        str(photo_files / "camera.yaml"),
        str(_prior(photo_files, "prior.json", HAND_PRIOR)),
        "--overlay",
        str(overlay),
        "--indent",
        "0",
    )
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["status"] == "ok", out["message"]
    # every outline sample on its edge (found where the box's colours end, not at the print's strongest gradient);
    # a real box's rounded edges fit to about a pixel and a quarter
    assert out["edges"]["share_on_edges"] > 0.9 and out["edges"]["rms_px"] < 1.5 and out["edges"]["samples"] > 250
    # every other start put the box's seen edges within three times that of this answer
    assert out["starts_apart_px"] < 3.0 * out["edges"]["rms_px"]
    assert len(out["features"]) >= 6  # of the 7 corners in view
    std = np.array(out["std"]["translation_mm"])
    assert np.all(std > 0.2) and np.all(
        std < 12.0
    )  # widened by the starts' spread (a nearly affine view: docs/find-points.md)
    # the corners alone (no sample shared with the edges) put the box where its edges do, within their scatter
    assert out["features_pose"]["origin_from_edges_mm"] < 3.0 * np.linalg.norm(std)
    # a corner the detector is unsure of says why (the box's far bottom corner: its edges are no straight lines)
    unsure = [f for f in out["features"] if f["confidence"] < 0.5]
    assert unsure and all(f.get("unsure_because") for f in unsure)
    assert not any("unsure_because" in f for f in out["features"] if f["confidence"] >= 0.5)
    R = np.array(out["R_obj2cam"])
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-6)
    picture = cv2.imread(str(overlay))
    assert picture is not None and picture.shape == (480, 718, 3)


def test_starts_around_the_prior_end_at_one_pose(photo_files):
    """Four starts 8 mm and 0.7 deg from the hand prior (searching 3 deg round it: the hand prior, from six corners
    picked to about 4 px, is itself 3 deg off the box's outline): each answer ``ok``, across the line of sight within
    their own 1-sigma (x3) of one another; in depth within 5 % (on this nearly affine view, 250 px of box at 1450 px
    focal, depth trades against the turn; docs/find-points.md)."""
    rng = np.random.default_rng(4)
    poses, stds = [], []
    for k in range(4):
        prior = _prior(photo_files, f"prior{k}.json", _moved(HAND_PRIOR, 8.0, 0.7, rng))
        run = _locate_box(
            [str(PHOTO)], str(photo_files / "camera.yaml"), str(prior), "--indent", "0", "--reach-deg", "3"
        )
        assert run.returncode == 0, run.stderr + run.stdout
        out = json.loads(run.stdout)
        assert out["status"] == "ok", out["message"]
        poses.append(np.array(out["t_obj2cam_mm"]))
        stds.append(np.array(out["std"]["translation_mm"]))
    spread = np.max(np.abs(np.array(poses) - np.mean(poses, axis=0)), axis=0)
    assert np.all(spread[:2] < 3.0 * np.max(stds, axis=0)[:2]), (spread, stds)
    assert spread[2] < 0.05 * np.mean(poses, axis=0)[2], (spread, stds)


def test_a_prior_too_far_says_not_located_with_exit_3(photo_files):
    far = {
        "R_obj2cam": HAND_PRIOR["R_obj2cam"],
        "t_obj2cam_mm": [150.0, 110.7, 943.5],
    }  # 150 mm to the side: off the box
    run = _locate_box([str(PHOTO)], str(photo_files / "camera.yaml"), str(_prior(photo_files, "far.json", far)))
    assert run.returncode == 3, run.stderr
    out = json.loads(run.stdout)
    assert out["status"] == "not found" and out["R_obj2cam"] is None and "prior" in out["message"]


@pytest.mark.parametrize(
    "bad, says",
    [
        ({"t_obj2cam_mm": [0, 0, 900]}, "R_obj2cam"),
        ({"R_obj2cam": [[1, 0], [0, 1]], "t_obj2cam_mm": [0, 0, 900]}, "3 x 3"),
        ({"R_obj2cam": [[2, 0, 0], [0, 1, 0], [0, 0, 1]], "t_obj2cam_mm": [0, 0, 900]}, "rotation"),
    ],
)
def test_a_bad_prior_is_one_error_line_naming_the_file(photo_files, bad, says):
    path = _prior(photo_files, "bad.json", bad)
    run = _locate_box([str(PHOTO)], str(photo_files / "camera.yaml"), str(path))
    assert run.returncode == 2 and run.stdout == ""
    assert (
        run.stderr.startswith("error: ")
        and str(path) in run.stderr
        and says in run.stderr
        and "Traceback" not in run.stderr
    )


def test_a_photo_of_another_size_than_the_camera_file_is_refused(photo_files):
    save_intrinsics(photo_files / "other.yaml", Intrinsics(1000, 1000, 320, 240, 640, 480))
    run = _locate_box([str(PHOTO)], str(photo_files / "other.yaml"), str(_prior(photo_files, "p.json", HAND_PRIOR)))
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "718" in run.stderr and "640" in run.stderr


def test_the_simulated_camera_s_frame_is_located_where_the_truth_is(tmp_path):
    """The test bed's fixture at the paper's task approach, the robot model's pose as the prior (its error: a few
    mm): edges only (the fixture's mesh has too many vertices for default corners). The truth only scores."""
    from calib_core.frames import concat, invert
    from calib_core.robot import solve_ik
    from tests.core.look.find_points_scenes import TARGET, errors_times
    from videocal_sim.test_bed import TestBed

    bed = TestBed.create(errors=errors_times(1.0))
    cell = bed.workcell
    q = solve_ik(bed.model_robot, cell.task("oru_1_grasp").approach2base, np.array(cell.home_joints_deg, float)).q_deg
    bed.joints_deg = q
    camera = bed.camera()
    try:
        frame = camera.read()
        truth = concat(cell.component(TARGET).item2world, invert(camera.last_truth.cam2world))
    finally:
        camera.close()
    item = cell.component(TARGET)
    model = concat(item.item2world, invert(bed.model_cam2world(q)))
    cv2.imwrite(str(tmp_path / "frame.png"), cv2.cvtColor(frame.image, cv2.COLOR_RGB2BGR))
    item.mesh.export(tmp_path / "fixture.stl")
    save_intrinsics(tmp_path / "camera.yaml", bed.intrinsics)
    _prior(tmp_path, "prior.json", {"R_obj2cam": model[:3, :3].tolist(), "t_obj2cam_mm": model[:3, 3].tolist()})
    # relative paths from the folder, as a user types them
    run = _videocal(
        "locate",
        "frame.png",
        "--mesh",
        "fixture.stl",
        "--intrinsics",
        "camera.yaml",
        "--prior",
        "prior.json",
        "--indent",
        "0",
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr + run.stdout
    out = json.loads(run.stdout)
    t = np.array(out["t_obj2cam_mm"])
    assert np.linalg.norm(t - truth[:3, 3]) < 0.5
    assert np.linalg.norm(t - model[:3, 3]) > 2.0  # it moved from the prior: the robot's error was found
    angle = np.degrees(Rotation.from_matrix(np.array(out["R_obj2cam"]) @ truth[:3, :3].T).magnitude())
    assert angle < 0.1
    assert np.linalg.norm(t - truth[:3, 3]) < 4.0 * np.linalg.norm(out["std"]["translation_mm"]) + 0.1


def test_several_photos_are_one_json_line_each_and_a_bad_one_does_not_stop_the_others(photo_files):
    """The tutorial's photo under two names with a broken photo between them: a line per photo in the order given,
    the same answer for the same photo, the broken one a line with its error (and one on stderr), exit 2; the
    overlays go to a folder, one per photo located."""
    import shutil

    again = photo_files / "again.jpg"
    shutil.copy(PHOTO, again)
    broken = photo_files / "broken.png"
    broken.write_bytes(b"not a PNG at all")
    overlays = photo_files / "overlays"
    run = _locate_box(
        [str(PHOTO), str(broken), str(again)],
        str(photo_files / "camera.yaml"),
        str(_prior(photo_files, "hand.json", HAND_PRIOR)),
        "--overlay",
        str(overlays),
    )
    assert run.returncode == 2, run.stderr
    lines = [json.loads(line) for line in run.stdout.splitlines()]
    assert [line["photo"] for line in lines] == [str(PHOTO), str(broken), str(again)]
    first, bad, second = lines
    assert first["status"] == "ok" and second["status"] == "ok", (first["message"], second["message"])
    np.testing.assert_allclose(first["t_obj2cam_mm"], second["t_obj2cam_mm"], atol=1e-6)
    assert bad["status"] == "error" and str(broken) in bad["error"] and "R_obj2cam" not in bad
    errors = [line for line in run.stderr.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and str(broken) in errors[0] and "Traceback" not in run.stderr
    assert sorted(p.name for p in overlays.iterdir()) == ["again.png", "resized_IMG_3875.png"]


def test_several_photos_with_an_overlay_file_name_are_refused_before_any_work(photo_files):
    run = _locate_box(
        [str(PHOTO), str(PHOTO)],
        str(photo_files / "camera.yaml"),
        str(_prior(photo_files, "hand.json", HAND_PRIOR)),
        "--overlay",
        str(photo_files / "one.png"),
    )
    assert run.returncode == 2 and run.stdout == "" and "Traceback" not in run.stderr
    assert "names a folder" in run.stderr and "one.png" in run.stderr
