"""``videocal calibrate-robot VIEWS.csv --grasps GRASPS.csv`` as a user runs it on files: board images
with their joints written from the cold cell, and the joints the controller reported with the gripper
closed on each task location's pin. The calibrated URDF at those joints puts its TCP on the pins; a
mistake in the grasps file is named before any work is done."""

import json
import re
import subprocess
import sys

import cv2
import numpy as np
import pytest

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.frames import pose_difference
from calib_core.robot.model import load_robot
from calib_core.robot_calibration.pose_planner import plan_poses
from videocal_sim.cold_cell import cold_test_bed
from calib_core.robot_calibration.cell_views import cell_view_joints
from videocal_sim.compliant_grasp import grasp_frame, grasp_joints
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from videocal_sim.hand_eye_views import simulated_hand_eye_images
from tests.terminal_run import run_on_terminal
from tests.tool_on_pins import assert_tool_on_the_pins


def _videocal(*args, timeout=600):
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *map(str, args)], capture_output=True, text=True, timeout=timeout
    )


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("robot_views")
    bed, _ = cold_test_bed(seed=1)
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, bed.workcell, bed.model_robot)
    plan = plan_poses(
        bed.model_robot,
        load_intrinsics(bed.workcell.intrinsics_path),
        spec,
        board2base,
        16,
        start_deg=bed.workcell.home_joints_deg,
        candidates=48,
    )
    rows = ["image," + ",".join(bed.model_robot.joint_names)]
    for name, image, q in simulated_hand_eye_images(bed, spec, plan.joints_deg, board2base):
        cv2.imwrite(str(folder / f"{name}.png"), image[:, :, ::-1])
        rows.append(f"{name}.png," + ",".join(f"{v:.6f}" for v in q))
    (folder / "views.csv").write_text("\n".join(rows) + "\n")
    grasps = {
        t.name: grasp_joints(bed, t.tcp2base, k, t.component)
        for k, t in enumerate(bed.workcell.task_locations.values())
    }
    (folder / "grasps.csv").write_text(
        "task,"
        + ",".join(f"j{k + 1}" for k in range(6))
        + "\n"
        + "".join(f"{name}," + ",".join(f"{v:.6f}" for v in q) + "\n" for name, q in grasps.items())
    )
    # The same board views and views of the surveyed components (the component column), and each grasp
    # with the camera's frame while it held the pin (the image column)
    tied = rows[:1] + [r.replace(".png,", ".png,,", 1) for r in rows[1:]]
    tied[0] = "image,component," + tied[0].split(",", 1)[1]
    targets = cell_view_joints(bed.model_robot, bed.workcell, load_intrinsics(bed.workcell.intrinsics_path), 2, 0)
    for k, (component, q) in enumerate(targets):
        cv2.imwrite(str(folder / f"cell_{k}.png"), grasp_frame(bed, q, k)[:, :, ::-1])
        tied.append(f"cell_{k}.png,{component}," + ",".join(f"{v:.6f}" for v in q))
    (folder / "views_tied.csv").write_text("\n".join(tied) + "\n")
    seen = ["task,image," + ",".join(f"j{k + 1}" for k in range(6))]
    for name, q in grasps.items():
        cv2.imwrite(str(folder / f"grasp_{name}.png"), grasp_frame(bed, q)[:, :, ::-1])
        seen.append(f"{name},grasp_{name}.png," + ",".join(f"{v:.6f}" for v in q))
    (folder / "grasps_seen.csv").write_text("\n".join(seen) + "\n")
    return folder, bed, grasps, len(targets)


def test_the_grasps_give_the_tool_and_the_urdf_carries_it(files, tmp_path):
    folder, bed, grasps, _ = files
    args = [
        "calibrate-robot",
        str(folder / "views.csv"),
        "--grasps",
        str(folder / "grasps.csv"),
        "--out",
        str(tmp_path),
    ]
    code, _, terminal = run_on_terminal(args, timeout=600)
    assert code == 0, terminal[-2000:]
    # on a terminal, the board's search through the views shows its progress: counts and the time left
    assert re.search(r"views: +\d+%.*\d+/16 \[\d\d:\d\d<\d\d:\d\d", terminal), terminal[-2000:]
    assert_tool_on_the_pins(tmp_path / "videocal_arm_calibrated.urdf", bed, grasps)
    assert "tcp2cam" in (tmp_path / "robot_calibration.yaml").read_text()


def test_component_views_tie_the_base_and_seen_grasps_give_the_tool(files, tmp_path):
    """The views CSV with a component column (views of the surveyed fixtures: their edges tie the base
    to the cell) and the grasps CSV with the frame of each grasp: the pins within 0.1 mm, scored by the
    truth (the compliance put the true TCP on each pin as it truly stands)."""
    folder, bed, grasps, n_cell = files
    run = _videocal(
        "calibrate-robot",
        folder / "views_tied.csv",
        "--grasps",
        folder / "grasps_seen.csv",
        "--out",
        tmp_path,
        "--json",
    )
    assert run.returncode == 0, run.stderr[-2000:]
    summary = json.loads(run.stdout)
    assert summary["cell_views"] >= n_cell - 1 and summary["board_views"] >= 12, summary
    assert summary["tool"]["seen"] == len(grasps), (summary, run.stderr[-1000:])
    robot = load_robot(tmp_path / "videocal_arm_calibrated.urdf")
    for name, q in grasps.items():
        task = bed.workcell.task(name)
        true_item = next(c for c in bed.true_components if c.name == task.component)
        pin = true_item.item2world @ np.linalg.inv(bed.workcell.component(task.component).item2world) @ task.tcp2base
        d, r = pose_difference(robot.fk(q, "tcp"), pin)
        assert np.linalg.norm(d) < 0.1 and np.linalg.norm(r) < 0.01, (name, d, r)


@pytest.mark.parametrize(
    "text, message",
    [
        (
            "task,j1,j2,j3,j4,j5,j6\nno_such_task,1,2,3,4,5,6\n",
            "row 2, task.*no task location 'no_such_task'.*oru_1_grasp",
        ),
        ("task,j1,j2,j3,j4,j5,j6\noru_1_grasp,1,2,x,4,5,6\n", "row 2, j3.*not a number: 'x'"),
        ("task,j1,j2,j3,j4,j5,j6\noru_1_grasp,1,2,3,4,5\n", "row 2.*6 values, the header has 7"),
        ("task,a,b,c,d,e,f\noru_1_grasp,1,2,3,4,5,6\n", "header.*not the robot's joints"),
        ("joints,j1,j2,j3,j4,j5,j6\n", "the first column must be 'task'"),
        ("task,j1,j2,j3,j4,j5,j6\noru_1_grasp,1,2,nan,4,5,6\n", "row 2, j3.*finite"),
        (
            "task,image,j1,j2,j3,j4,j5,j6\noru_1_grasp,missing.png,1,2,3,4,5,6\n",
            "row 2, image.*no such image .*missing.png",
        ),
    ],
)
def test_a_wrong_grasps_file_is_named_before_any_work(files, tmp_path, text, message):
    folder, _, _, _ = files
    bad = tmp_path / "grasps.csv"
    bad.write_text(text)
    run = _videocal("calibrate-robot", folder / "views.csv", "--grasps", bad, "--out", tmp_path / "out", timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "grasps.csv" in run.stderr
    assert re.search(message, run.stderr), run.stderr
    assert not (tmp_path / "out").exists()


def test_a_view_of_a_component_the_cell_does_not_survey_is_named_before_any_work(files, tmp_path):
    folder, _, _, _ = files
    lines = (folder / "views_tied.csv").read_text().splitlines()
    name, _, rest = lines[-1].split(",", 2)
    bad = folder / "views_bad_component.csv"
    bad.write_text("\n".join(lines[:-1] + [f"{name},no_such_part,{rest}"]) + "\n")
    run = _videocal("calibrate-robot", bad, "--out", tmp_path / "out", timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert re.search(
        r"views_bad_component.csv: view cell_\d+: no surveyed component 'no_such_part'.*oru_1_fixture", run.stderr
    ), run.stderr
    assert not (tmp_path / "out").exists()


def test_a_folder_holds_the_views_and_the_grasps(files, tmp_path):
    """``calibrate-robot FOLDER``: its views.csv, and its grasps.csv without --grasps (said so)."""
    folder, _, grasps, _ = files
    run = _videocal("calibrate-robot", folder, "--out", tmp_path, "--json")
    assert run.returncode == 0, run.stderr[-2000:]
    assert "grasps from" in run.stderr and json.loads(run.stdout)["tool"]["grasps"] == len(grasps)
    empty = tmp_path / "empty"
    empty.mkdir()
    run = _videocal("calibrate-robot", empty, "--out", tmp_path / "out", timeout=120)
    assert (
        run.returncode == 2
        and "Traceback" not in run.stderr
        and "cal_data.yaml" in run.stderr
        and "views.csv" in run.stderr
    )
