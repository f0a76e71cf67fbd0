"""``videocal calibrate-robot BAG``: the robot's geometry identified from a user's ROS 2 bag with no
conversion: board images on a compressed topic, ``/joint_states`` (SI units, a gripper joint beside the arm's)
and the camera driver's CameraInfo, recorded while the arm held still at planned poses and moved between them.
Frames taken mid-move are left out; the joints of the others come from the joint states at each image's stamp.
The cold test bed's truth only scores: the calibrated URDF puts the TCP on each task's pin."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.robot_calibration.pose_planner import plan_poses
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from tests.core.bags.bag_writing import hold_and_move, write_arm_bag
from tests.tool_on_pins import assert_tool_on_the_pins
from videocal_sim.cold_cell import cold_test_bed
from videocal_sim.compliant_grasp import grasp_joints
from videocal_sim.hand_eye_views import simulated_hand_eye_images

ROOT = Path(__file__).resolve().parents[3]
T0 = 1_760_000_000_000_000_000  # the robot's clock, ns


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    bed, _ = cold_test_bed(seed=1)
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, bed.workcell, bed.model_robot)
    nominal = load_intrinsics(
        bed.workcell.intrinsics_path
    )  # what the camera's driver publishes: its data sheet's, not the truth
    plan = plan_poses(
        bed.model_robot, nominal, spec, board2base, 16, start_deg=bed.workcell.home_joints_deg, candidates=48
    )
    track, shot_at, moving = hold_and_move(plan.joints_deg, T0)
    rendered = simulated_hand_eye_images(bed, spec, [q for _, q in shot_at], board2base)
    folder = tmp_path_factory.mktemp("robot_bag")
    bag = write_arm_bag(
        folder / "robot_bag",
        nominal,
        bed.model_robot,
        [(t, image) for (t, _), (_, image, _) in zip(shot_at, rendered)],
        track,
    )
    grasps = {
        t.name: grasp_joints(bed, t.tcp2base, k, t.component)
        for k, t in enumerate(bed.workcell.task_locations.values())
    }
    grasps_csv = folder / "grasps.csv"
    grasps_csv.write_text(
        "task,"
        + ",".join(f"j{k + 1}" for k in range(6))
        + "\n"
        + "".join(f"{name}," + ",".join(f"{v:.6f}" for v in q) + "\n" for name, q in grasps.items())
    )
    return bag, grasps_csv, bed, grasps, len(plan.joints_deg), moving


def test_the_robot_from_a_bag_of_images_and_joint_states(recorded, tmp_path):
    bag, grasps_csv, bed, grasps, still, moving = recorded
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-robot",
            str(bag),
            "--grasps",
            str(grasps_csv),
            "--out",
            str(tmp_path),
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=900,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert f"{still + moving} images, {still} taken while the arm stood still" in run.stderr
    assert run.stderr.count("skipped ") == moving and run.stderr.count("not a still view") == moving
    summary = json.loads(run.stdout)
    assert summary["board_views"] == still, summary  # every still frame shows the whole board
    # As from the same views in a CSV (tests/cli/test_calibrate_robot_files_cli.py).
    assert_tool_on_the_pins(tmp_path / "videocal_arm_calibrated.urdf", bed, grasps)


def test_a_bag_with_no_still_board_view_is_an_error_not_an_empty_fit(recorded, tmp_path):
    bag, *_ = recorded
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-robot",
            str(bag),
            "--joint-topic",
            "/other_joint_states",
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert (
        run.returncode == 2
        and run.stderr.startswith("error: ")
        and "no JointState topic /other_joint_states" in run.stderr
    ), run.stderr
    assert not (tmp_path / "out").exists()
