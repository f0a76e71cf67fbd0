"""The camera's mounting from a user's ROS 2 bag with no conversion: board images, ``/joint_states`` and
CameraInfo as a ROS 2 system records them (written by ``rosbags``), from the simulated test bed: the arm holds still
at each pose and moves between them, and the camera keeps taking frames all along. The flange pose at each image's
stamp comes from the joint states through the cell's robot, only where the arm stood still; the intrinsics from the
CameraInfo. The truth only scores."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from calib_core.frames import concat, invert, pose_difference
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from calib_core.workcell import load_workcell
from tests.core.bags.bag_writing import hold_and_move, write_arm_bag
from videocal_sim.hand_eye_views import hand_eye_poses, simulated_hand_eye_images
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

ROOT = Path(__file__).resolve().parents[3]
T0 = 1_760_000_000_000_000_000  # the robot's clock, ns


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cell = load_workcell()
    typical = RobotErrors.typical(0, n_joints=cell.load_robot().n_joints)
    bed = TestBed.create(
        cell, errors=RobotErrors(hand_eye_xyz_mm=typical.hand_eye_xyz_mm, hand_eye_rpy_deg=typical.hand_eye_rpy_deg)
    )
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, cell, bed.model_robot)
    poses = hand_eye_poses(bed, spec, board2base, 8)
    track, shot_at, moving = hold_and_move(poses, T0)
    rendered = simulated_hand_eye_images(bed, spec, [q for _, q in shot_at], board2base)
    shots = [(t, image) for (t, _), (_, image, _) in zip(shot_at, rendered)]
    folder = tmp_path_factory.mktemp("bag")
    bag = write_arm_bag(folder / "hand_eye_bag", bed.intrinsics, bed.model_robot, shots, track)
    tf_bag = write_arm_bag(
        folder / "tf_bag", bed.intrinsics, bed.model_robot, shots, track, joint_states=False, tf=True
    )
    true_robot = bed.true_robot.robot
    truth = concat(true_robot.frame_placement("camera"), invert(true_robot.frame_placement("flange")))
    return bag, truth, len(poses), moving, tf_bag


def test_the_mounting_from_a_bag_of_images_and_joint_states(recorded, tmp_path):
    bag, truth, still, moving, _ = recorded
    out = tmp_path / "mount.yaml"
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "calibrate-hand-eye", str(bag), "--out", str(out), "--json"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    doc = json.loads(run.stdout)
    assert doc["poses"] == still  # every still frame, no frame taken while the arm moved
    assert run.stderr.count("not a still view") == moving
    assert f"{still + moving} images, {still} taken while the arm stood still" in run.stderr
    from calib_core.vision.hand_eye_io import load_cam2flange

    d, r = pose_difference(load_cam2flange(out), truth)
    assert np.linalg.norm(d) < 1.0 and np.linalg.norm(r) < 0.1, (d, r)


def test_a_bag_without_this_robot_s_joints_says_what_it_names(recorded, tmp_path):
    bag, *_ = recorded
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-hand-eye",
            str(bag),
            "--joint-topic",
            "/other_joint_states",
            "--out",
            str(tmp_path / "x.yaml"),
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
    )
    assert "/joint_states (sensor_msgs/msg/JointState)" in run.stderr  # what the bag holds, named


def test_the_mounting_from_a_bag_with_the_flange_on_tf(recorded, tmp_path):
    """No joint states: the flange from ``/tf`` (a streamed edge and a latched one in the chain, a frame above the base
    beside it), still frames only, as from the joints."""
    _, truth, still, moving, tf_bag = recorded
    out = tmp_path / "mount.yaml"
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "calibrate-hand-eye", str(tf_bag), "--out", str(out), "--json"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    assert "the flange (flange in base_link) from /tf" in run.stderr
    assert json.loads(run.stdout)["poses"] == still and run.stderr.count("not a still view") == moving
    from calib_core.vision.hand_eye_io import load_cam2flange

    d, r = pose_difference(load_cam2flange(out), truth)
    assert np.linalg.norm(d) < 1.0 and np.linalg.norm(r) < 0.1, (d, r)
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-hand-eye",
            str(tf_bag),
            "--flange-frame",
            "tool0",
            "--out",
            str(tmp_path / "x.yaml"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert run.returncode == 2 and run.stderr.startswith("error: "), run.stderr
    assert (
        "no chain of transforms from 'tool0' up to 'base_link'" in run.stderr
        and "frames: base_link, flange, forearm, world" in run.stderr
    )
