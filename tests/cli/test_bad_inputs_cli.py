"""The bad inputs of "Hardening" item 7 and 8, through the real command line: each ends with one
``error:`` line naming the file or option at fault and exit 2, no traceback, and within a bound on
the child's memory (a 22 GiB allocation or a YAML alias bomb would blow it). The time and memory
each one takes are measured in bench/reliability_bench.py, not here."""

import json
import os
import resource
import shutil
import subprocess
from pathlib import Path

import pytest
import yaml

from calib_core.workcell import DEFAULT_WORKCELL
from tests.cli.refused_runs import limits, refused, videocal


@pytest.fixture
def cell(tmp_path):
    """A copy of the bundled cell (workcell, meshes, robot, camera) to break; returns a function that
    writes the workcell with ``edit(data)`` applied and returns its path."""
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(root / sub, tmp_path / sub)
    path = tmp_path / "workcell" / "workcell.yaml"

    def write(edit=None, text: str | None = None) -> Path:
        if text is None:
            data = yaml.safe_load(path.read_text())
            if edit is not None:
                edit(data)
            text = yaml.safe_dump(data, sort_keys=False)
        out = tmp_path / "workcell" / "edited.yaml"
        out.write_text(text)
        return out

    write.folder = tmp_path
    return write


def _render(workcell: Path, tmp: Path) -> subprocess.CompletedProcess:
    return videocal("render", "--workcell", workcell, "--out", tmp / "out.png", "--scale", "0.25")


# --- documents that are too deep, too big, too aliased --------------------------------------------
def test_a_workcell_nested_10000_deep(cell):
    deep = "name: " + "[" * 10000 + "]" * 10000 + "\n"
    refused(_render(cell(text=deep), cell.folder), "edited.yaml", "nests deeper than")


def test_a_json_nested_10000_deep(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text("[" * 10000 + "]" * 10000)
    refused(videocal("solve", path), "deep.json", "nests deeper than")
    refused(videocal("export", path), "deep.json", "nests deeper than")


def test_an_alias_bomb_in_a_workcell_name(cell):
    bomb = "".join(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]\n" for i in range(1, 9))
    text = cell().read_text().replace("name: space station robotic test bed", "a0: &a0 [x]\n" + bomb + "name: *a8")
    refused(_render(cell(text=text), cell.folder), "edited.yaml", "aliases")


def test_a_huge_all_comment_workcell(cell):
    path = cell.folder / "workcell" / "comments.yaml"
    with open(path, "w") as f:
        line = "# " + "x" * 98 + "\n"
        for _ in range(170_000):  # 17 MB
            f.write(line)
    refused(_render(path, cell.folder), "comments.yaml", "at most")


# --- fields of the wrong type or out of range -----------------------------------------------------
def test_a_workcell_without_a_camera(cell):
    for edit in (lambda d: d.pop("camera"), lambda d: d.update(camera=None)):
        refused(_render(cell(edit), cell.folder), "camera")


def test_a_task_component_given_as_a_list(cell):
    def edit(d):
        d["task_locations"][0]["component"] = ["oru_1", "oru_2"]

    refused(_render(cell(edit), cell.folder), "component")


def _camera_file(cell, text: str) -> Path:
    (cell.folder / "camera" / "bad.yaml").write_text(text)
    return cell(lambda d: d.update(camera={"intrinsics": "../camera/bad.yaml"}))


def test_an_opencv_intrinsics_file_whose_rows_and_cols_disagree_with_its_data(cell):
    text = (cell.folder / "camera" / "gripper_camera.yaml").read_text().replace("rows: 3", "rows: 4", 1)
    refused(_render(_camera_file(cell, text), cell.folder), "bad.yaml", "camera_matrix")


def test_ros_rows_given_as_text_and_an_absurd_image_size(cell):
    ros = yaml.safe_load((cell.folder / "camera" / "gripper_camera_ros.yaml").read_text())
    text = yaml.safe_dump({**ros, "camera_matrix": {**ros["camera_matrix"], "rows": "3"}})
    refused(_render(_camera_file(cell, text), cell.folder), "bad.yaml", "camera_matrix.rows")
    huge = yaml.safe_dump({**ros, "image_width": 10**12})
    refused(_render(_camera_file(cell, huge), cell.folder), "bad.yaml", "image_width")


def _stored(task: str, model, measured, kind: str = "correction"):
    """A look's result stored for ``task``: the TCP 1 mm off its model along x, 6 pairs at 0.3 px."""
    import numpy as np

    from calib_core.calibration.corrections import Correction

    return Correction(
        task,
        model,
        measured,
        np.array([1.0, 0, 0]),
        np.zeros(3),
        np.full(3, 0.1),
        np.full(3, 0.01),
        np.zeros(6),
        0.3,
        6,
        kind=kind,
    )


def test_export_with_std_or_time_as_objects(tmp_path):
    import numpy as np

    from calib_core.calibration.corrections import CorrectionTable
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import Workspace, save_workspace

    cell = load_workcell()
    table = CorrectionTable()
    measured = np.eye(4)
    measured[0, 3] = 1.0
    table.add(_stored("oru_1_grasp", np.eye(4), measured))
    path = tmp_path / "w.json"
    save_workspace(
        path,
        Workspace(
            str(cell.path), load_intrinsics(cell.intrinsics_path), dict(cell.task_locations), "oru_1_fixture", [], table
        ),
    )
    assert videocal("export", path).returncode == 0
    original = json.loads(path.read_text())
    for field, value in (
        ("std_displacement_mm", {"x": 1}),
        ("time_s", {"when": "now"}),
        ("std_rotation_deg", [0.1, 0.1]),
    ):
        data = json.loads(json.dumps(original))
        data["corrections"][0][field] = value
        path.write_text(json.dumps(data))
        refused(videocal("export", path), "w.json", field)


def test_a_recorded_solve_without_its_result(tmp_path):
    from calib_core.recording.recorder import SessionRecorder
    from calib_core.recording.schemas import SOLVE_TOPIC

    path = tmp_path / "s.mcap"
    with SessionRecorder(path) as rec:
        rec._write(SOLVE_TOPIC, {"id": 1, "inputs": {}})
    refused(videocal("replay", path), "s.mcap", "solve 1")


# --- options out of range -------------------------------------------------------------------------
@pytest.mark.parametrize(
    "args, expected",
    [
        (("calibrate-intrinsics", "sim", "--views", "0", "--out", "{tmp}/i.yaml"), "--views"),
        (
            (
                "calibrate-intrinsics",
                "sim",
                "--board",
                "charuco:100000x100000:30:22:DICT_5X5_100",
                "--out",
                "{tmp}/i.yaml",
            ),
            "board",
        ),
        (("calibrate-hand-eye", "sim", "--poses", "1000000", "--out", "{tmp}/h.yaml"), "--poses"),
        (("demo", "--offscreen", "--scale", "100", "--out", "{tmp}/demo"), "--scale"),
        (("demo", "--offscreen", "--out", "{tmp}/a_file"), "a_file"),
        (("monitor", "loop://", "--timeout", "nan"), "--timeout"),
        (("monitor", "loop://", "--timeout", "inf"), "--timeout"),
        (("render", "--scale", "1e6", "--out", "{tmp}/r.png"), "--scale"),
    ],
)
def test_options_out_of_range(tmp_path, args, expected):
    (tmp_path / "a_file").write_text("I am a file, not a folder")
    refused(videocal(*[a.format(tmp=tmp_path) for a in args]), expected)


def test_a_full_disk_is_an_error_not_a_traceback(tmp_path):
    def small_files() -> None:
        import signal

        limits()
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))

    out = tmp_path / "r.png"
    run = videocal("render", "--out", out, "--scale", "0.5", preexec=small_files)
    refused(run, "r.png")
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_board_views_too_small_or_of_no_camera_s_shape_are_rejected_by_name(tmp_path):
    """A 1 x 1 PNG failed OpenCV's adaptive threshold with a traceback; a damaged JPEG that decodes as 640 x 14304
    made the board detector allocate past 2 GB. Each is now a rejected view, named with its size."""
    import cv2
    import numpy as np

    folder = tmp_path / "views"
    folder.mkdir()
    cv2.imwrite(str(folder / "one.png"), np.zeros((1, 1), np.uint8))
    cv2.imwrite(str(folder / "tall.jpg"), np.random.default_rng(0).integers(0, 255, (14304, 640), dtype=np.uint8))
    line = refused(
        videocal("calibrate-intrinsics", folder, "--board", "chessboard:9x6:25", "--out", tmp_path / "camera.yaml"),
        "one.png: the image is 1 x 1 px: too small",
        "tall.jpg: the image is 640 x 14304 px: not a camera's picture",
    )
    assert "0 usable board views" in line and not (tmp_path / "camera.yaml").exists()


def test_grab_into_a_folder_under_a_file_or_from_no_camera_leaves_nothing(tmp_path):
    (tmp_path / "afile").write_text("x")
    refused(
        videocal("grab", "file:nothing.png", "--count", "1", "--out", tmp_path / "afile" / "sub"), "afile is a file"
    )
    refused(
        videocal("grab", str(tmp_path / "missing.mp4"), "--count", "1", "--out", tmp_path / "new" / "frames"),
        "missing.mp4",
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]  # no folder made for a camera that did not open


# --- numbers that parse but mean nothing --------------------------------------------------------------
def test_a_feature_at_1e23_mm_and_a_distortion_of_minus_1e308_are_refused_by_field(cell):
    def far_feature(d):
        component = next(c for c in d["components"] if c.get("features"))
        name = next(iter(component["features"]))
        component["features"][name] = [1e23, 0.0, 0.0]

    refused(_render(cell(far_feature), cell.folder), "edited.yaml", "features", "beyond")

    def far_board(d):
        d["hand_eye_board"] = {"xyz": [1e308, 0.0, 0.0], "rpy": [0.0, 0.0, 0.0]}

    def turned_part(d):
        d["components"][0]["placement"]["rpy"] = [1e23, 0.0, 0.0]

    refused(_render(cell(far_board), cell.folder), "edited.yaml", "hand_eye_board.xyz", "beyond 1e+07 mm")
    refused(_render(cell(turned_part), cell.folder), "edited.yaml", "components[0].placement.rpy", "beyond 3600 deg")
    ros = yaml.safe_load((cell.folder / "camera" / "gripper_camera_ros.yaml").read_text())
    ros["distortion_coefficients"]["data"][1] = -1e308
    refused(_render(_camera_file(cell, yaml.safe_dump(ros)), cell.folder), "bad.yaml", "k2", "no lens")


def test_a_camera_mounting_10_km_from_the_flange_is_refused(tmp_path):
    from calib_core.errors import FileFormatError
    from calib_core.vision.hand_eye_io import load_mounting

    path = tmp_path / "hand_eye.yaml"
    path.write_text(yaml.safe_dump({"cam2flange": {"xyz": [1e7, 0.0, 0.0], "rpy": [0.0, 0.0, 0.0]}}))
    with pytest.raises(
        FileFormatError, match=r"hand_eye.yaml: field 'cam2flange.xyz': the camera would be 10000000 mm from"
    ):
        load_mounting(path)


def test_a_workspace_pair_at_minus_1e308_or_a_sigma_of_9e18_is_not_exported(tmp_path):
    import numpy as np

    from calib_core.calibration.corrections import CorrectionTable
    from calib_core.calibration.correspondences import Correspondence
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import Workspace, save_workspace

    cell = load_workcell()
    table = CorrectionTable()
    measured = np.eye(4)
    measured[0, 3] = 1.0
    table.add(_stored("oru_1_grasp", np.eye(4), measured))
    pair = Correspondence(1, "oru_1_fixture", None, (100.0, 0.0, 0.0), None)
    path = tmp_path / "w.json"
    save_workspace(
        path,
        Workspace(
            str(cell.path),
            load_intrinsics(cell.intrinsics_path),
            dict(cell.task_locations),
            "oru_1_fixture",
            [pair],
            table,
        ),
    )
    assert videocal("export", path).returncode == 0
    original = json.loads(path.read_text())
    data = json.loads(json.dumps(original))
    data["pairs"][0]["point_world_mm"] = [-1e308, 0.0, 0.0]
    path.write_text(json.dumps(data))
    refused(videocal("export", path), "w.json", "point_world_mm", "within")
    data = json.loads(json.dumps(original))
    data["corrections"][0]["std_displacement_mm"] = [9e18, 0.1, 0.1]
    path.write_text(json.dumps(data))
    refused(videocal("export", path), "w.json", "std_displacement_mm", "up to")


def test_a_site_url_with_a_newline_or_a_nul_is_refused_by_field(cell):
    for url in ("socket://robot:30002\nmore", "ros2:///joint_states\x00"):
        refused(
            _render(cell(lambda d: d.update(site={"controller": url})), cell.folder),
            "edited.yaml",
            "site.controller",
            "control character",
        )


def test_new_cell_on_a_full_disk_or_a_read_only_folder_says_so_and_leaves_nothing(tmp_path):
    """new-cell wrote its meshes, then failed on a full disk with a traceback and a half-made folder."""
    import stat

    from tests.vendor_robots import SHARE, UR5, require

    def small_files() -> None:
        import signal

        limits()
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (1500, 1500))  # the workcell file and the target's STL are larger

    urdf = require(UR5)
    run = videocal(
        "new-cell",
        tmp_path / "deep" / "cell",
        "--urdf",
        urdf,
        "--package-path",
        SHARE,
        preexec=small_files,
        timeout=300,
    )
    refused(run, "cell", "nothing was left behind")
    assert list(tmp_path.iterdir()) == []
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        if os.geteuid() != 0:  # root writes anywhere: the read-only case is a user's
            refused(videocal("new-cell", locked / "cell", "--urdf", urdf, "--package-path", SHARE, timeout=300), "cell")
            assert list(locked.iterdir()) == []
    finally:
        locked.chmod(stat.S_IRWXU)


def test_joints_whose_first_is_negative_given_as_two_tokens_say_how_to_write_them():
    run = videocal("render", "--joints", "-5,0,0,0,0,0", "--out", "never.png")
    refused(run, "argument --joints: expected one argument", "--joints=VALUE", "--joints=-20,10,30")


def test_an_export_of_a_task_holding_only_a_measurement_leaves_it_out_and_says_so(tmp_path):
    """A look made elsewhere kept as a measurement: every controller listing failed on it with a traceback. Alone it
    is a clear refusal (nothing to command); beside a correction, the listing holds the correction's target only and
    a line says which task was left out and why."""

    from calib_core.calibration.corrections import CorrectionTable
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.workcell import load_workcell
    from calib_core.workspace.workspace import Workspace, save_workspace

    cell = load_workcell()
    tasks = dict(cell.task_locations)
    names = list(tasks)

    def stored(task, kind):
        measured = tasks[task].tcp2base.copy()
        measured[0, 3] += 1.0
        return _stored(task, tasks[task].tcp2base, measured, kind)

    table = CorrectionTable()
    table.add(stored(names[0], "measurement"))
    path = tmp_path / "w.json"
    intrinsics = load_intrinsics(cell.intrinsics_path)
    save_workspace(path, Workspace(str(cell.path), intrinsics, tasks, "oru_1_fixture", [], table))
    for fmt in ("urscript", "rapid", "krl", "fanuc", "pdl2"):
        said = refused(videocal("export", path, "--format", fmt), "no task location holds a correction", names[0])
        assert "only a measurement" in said
    table.add(stored(names[1], "correction"))
    save_workspace(path, Workspace(str(cell.path), intrinsics, tasks, "oru_1_fixture", [], table))
    run = videocal("export", path, "--format", "urscript")
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    assert f"global {names[1]}" in run.stdout and names[0] not in run.stdout
    assert f"{names[0]}: left out, it holds only a measurement" in run.stderr
