"""The camera's mounting from a user's ROS 2 bag with no conversion (issue 31): board images, ``/joint_states`` and
CameraInfo as a ROS 2 system records them (written by ``rosbags``), from the simulated test bed: the arm holds still
at each pose and moves between them, and the camera keeps taking frames all along. The flange pose at each image's
stamp comes from the joint states through the cell's robot, only where the arm stood still; the intrinsics from the
CameraInfo. The truth only scores."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from calib_core.frames import concat, invert, pose_difference
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from calib_core.workcell import load_workcell
from videocal_sim.hand_eye_views import hand_eye_poses, simulated_hand_eye_images
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

ROOT = Path(__file__).resolve().parents[3]
T0 = 1_760_000_000_000_000_000  # the robot's clock, ns
HOLD_S, MOVE_S, RATE_HZ = 1.0, 1.0, 100.0


def _write_bag(folder: Path, bed: TestBed, shots: list[tuple[int, np.ndarray]], track: list[tuple[int, np.ndarray]]) -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    stamp = lambda t: Time(sec=t // 10**9, nanosec=t % 10**9)  # noqa: E731
    robot = bed.model_robot
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        images = writer.add_connection("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage", typestore=ts)
        info = writer.add_connection("/camera/camera_info", "sensor_msgs/msg/CameraInfo", typestore=ts)
        joints = writer.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        intr = bed.intrinsics
        roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
        camera_info = T["sensor_msgs/msg/CameraInfo"](header=Header(stamp=stamp(T0), frame_id="camera_optical_frame"), height=intr.height, width=intr.width,
                                                       distortion_model="plumb_bob", d=np.array(intr.distortion, float),
                                                       k=np.array([intr.fu, 0, intr.cx, 0, intr.fv, intr.cy, 0, 0, 1.0]), r=np.eye(3).ravel(), p=np.zeros(12),
                                                       binning_x=0, binning_y=0, roi=roi)
        writer.write(info, T0, ts.serialize_cdr(camera_info, "sensor_msgs/msg/CameraInfo"))
        names = list(robot.joint_names) + ["gripper_finger"]  # the gripper's joint in the same message, as many drivers do
        si = np.array([math.pi / 180.0 if u == "deg" else 1e-3 for u in robot.joint_units])
        for t, q in track:
            msg = T["sensor_msgs/msg/JointState"](header=Header(stamp=stamp(t), frame_id=""), name=names, position=np.append(q * si, 0.01),
                                                  velocity=np.array([], float), effort=np.array([], float))
            writer.write(joints, t + 2_000_000, ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))  # recorded 2 ms after its stamp
        for t, image in shots:
            ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 95])
            msg = T["sensor_msgs/msg/CompressedImage"](header=Header(stamp=stamp(t), frame_id="camera_optical_frame"), format="jpeg", data=np.frombuffer(jpeg.tobytes(), np.uint8))
            writer.write(images, t + 30_000_000, ts.serialize_cdr(msg, "sensor_msgs/msg/CompressedImage"))
    return folder


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    cell = load_workcell()
    typical = RobotErrors.typical(0, n_joints=cell.load_robot().n_joints)
    bed = TestBed.create(cell, errors=RobotErrors(hand_eye_xyz_mm=typical.hand_eye_xyz_mm, hand_eye_rpy_deg=typical.hand_eye_rpy_deg))
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, cell, bed.model_robot)
    poses = hand_eye_poses(bed, spec, board2base, 8)
    # the timeline: hold each pose, then move to the next; a frame mid-hold and one mid-move
    track, shot_at = [], []
    t = T0
    for k, q in enumerate(poses):
        for j in range(int(HOLD_S * RATE_HZ)):
            track.append((t + int(j / RATE_HZ * 1e9), np.asarray(q, float)))
        shot_at.append((t + int(HOLD_S / 2 * 1e9), np.asarray(q, float)))
        t += int(HOLD_S * 1e9)
        if k + 1 < len(poses):
            for j in range(int(MOVE_S * RATE_HZ)):
                f = j / (MOVE_S * RATE_HZ)
                track.append((t + int(j / RATE_HZ * 1e9), (1 - f) * np.asarray(q, float) + f * np.asarray(poses[k + 1], float)))
            shot_at.append((t + int(MOVE_S / 2 * 1e9), 0.5 * (np.asarray(q, float) + np.asarray(poses[k + 1], float))))
            t += int(MOVE_S * 1e9)
    rendered = simulated_hand_eye_images(bed, spec, [q for _, q in shot_at], board2base)
    shots = [(ts_, image) for (ts_, _), (_, image, _) in zip(shot_at, rendered)]
    bag = _write_bag(tmp_path_factory.mktemp("bag") / "hand_eye_bag", bed, shots, track)
    true_robot = bed.true_robot.robot
    truth = concat(true_robot.frame_placement("camera"), invert(true_robot.frame_placement("flange")))
    return bag, truth, len(poses), len(poses) - 1


def test_the_mounting_from_a_bag_of_images_and_joint_states(recorded, tmp_path):
    bag, truth, still, moving = recorded
    out = tmp_path / "mount.yaml"
    run = subprocess.run([sys.executable, "-m", "app.cli.main", "calibrate-hand-eye", str(bag), "--out", str(out), "--json"],
                         capture_output=True, text=True, timeout=600, cwd=ROOT)
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
    run = subprocess.run([sys.executable, "-m", "app.cli.main", "calibrate-hand-eye", str(bag), "--joint-topic", "/other_joint_states", "--out", str(tmp_path / "x.yaml")],
                         capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert run.returncode == 2 and run.stderr.startswith("error: ") and "no JointState topic /other_joint_states" in run.stderr
    assert "/joint_states (sensor_msgs/msg/JointState)" in run.stderr  # what the bag holds, named
