"""A recording as a ROS 2 bag, read back by rosbags' AnyReader (the reader ROS 2 users' Python tools use): the
frames, the joint states in radians in the URDF's names, the camera_info; a bad export loses nothing."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from calib_core.bags.bag_export import IMAGE_TOPIC, INFO_TOPIC, JOINT_TOPIC, recording_to_bag
from calib_core.errors import FileFormatError
from calib_core.recording.frame_track import FrameTrack
from calib_core.recording.reader import read_recording
from calib_core.recording.schemas import JOINTS_TOPIC, SETUP_TOPIC

SAMPLE = Path(__file__).resolve().parents[3] / "resources" / "recordings" / "sample_session.mcap"


def test_the_sample_session_reads_back_as_ros_messages(tmp_path):
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = tmp_path / "session_bag"
    counts = recording_to_bag(SAMPLE, out, joint_units=["deg"] * 6)
    contents = read_recording(SAMPLE)
    track = FrameTrack(contents)
    samples = contents.topic(JOINTS_TOPIC)
    setup = contents.topic(SETUP_TOPIC)[-1].payload
    assert counts[JOINT_TOPIC] == len(samples) and 0 < counts[IMAGE_TOPIC] <= len(track)
    assert counts[INFO_TOPIC] == counts[IMAGE_TOPIC]  # a CameraInfo with every image (it had one for 139 images)
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        topics = {c.topic: c.msgtype for c in reader.connections}
        assert topics == {
            IMAGE_TOPIC: "sensor_msgs/msg/CompressedImage",
            JOINT_TOPIC: "sensor_msgs/msg/JointState",
            INFO_TOPIC: "sensor_msgs/msg/CameraInfo",
        }
        states = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == JOINT_TOPIC])
        ]
        images = [
            (t, reader.deserialize(raw, c.msgtype))
            for c, t, raw in reader.messages([c for c in reader.connections if c.topic == IMAGE_TOPIC])
        ]
        infos = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == INFO_TOPIC])
        ]
        info = infos[0]
    # each image's CameraInfo has its stamp and frame, as image_proc pairs them
    assert [(m.header.stamp.sec, m.header.stamp.nanosec, m.header.frame_id) for m in infos] == [
        (m.header.stamp.sec, m.header.stamp.nanosec, m.header.frame_id) for _, m in images
    ]
    assert list(states[0].name) == list(setup["joint_names"])
    np.testing.assert_allclose(
        states[5].position, np.radians(samples[5].payload["joints_deg"]), atol=1e-12
    )  # deg -> rad
    assert states[5].header.stamp.sec * 10**9 + states[5].header.stamp.nanosec == samples[5].log_time_ns
    first = cv2.cvtColor(cv2.imdecode(np.asarray(images[0][1].data), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    original = track.image(next(k for k in range(len(track)) if track.image(k) is not None))
    assert first.shape == original.shape and np.abs(first.astype(int) - original.astype(int)).mean() < 3.0  # JPEG at 92
    i = setup["intrinsics"]
    assert (
        (info.width, info.height) == (i["width"], i["height"])
        and info.k[0] == i["fu"]
        and info.k[2] == i["cx"]
        and info.distortion_model == "plumb_bob"
    )


def test_a_prismatic_joint_goes_out_in_metres(tmp_path):
    """ROS's JointState is in radians and metres: a joint the robot says is in mm is divided by 1000, not by 57.3."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    out = tmp_path / "bag"
    recording_to_bag(SAMPLE, out, joint_units=["deg"] * 5 + ["mm"])
    sample = read_recording(SAMPLE).topic(JOINTS_TOPIC)[3].payload["joints_deg"]
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        states = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == JOINT_TOPIC])
        ]
    np.testing.assert_allclose(states[3].position, list(np.radians(sample[:5])) + [sample[5] / 1000.0], atol=1e-12)


def test_a_bad_export_says_why_and_leaves_nothing(tmp_path):
    out = tmp_path / "bag"
    out.mkdir()
    with pytest.raises(FileFormatError, match="exists already"):
        recording_to_bag(SAMPLE, out, joint_units=["deg"] * 6)
    assert list(out.iterdir()) == []  # nothing written into the folder that was there
    with pytest.raises(FileFormatError, match="which is not there: give --workcell"):
        from calib_core.bags import bag_export

        bag_export._units_from_workcell(SAMPLE, str(Path(__file__).resolve().parents[2] / "data" / "nope.yaml"), 6)
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "export", str(SAMPLE), "--format", "ros2-bag"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "give --out FOLDER" in run.stderr and "Traceback" not in run.stderr


def test_a_full_disk_is_one_error_line_and_no_half_written_bag(tmp_path):
    """A file-size limit as a full disk: export --format ros2-bag ended in rosbags' traceback."""
    import resource
    import signal

    def small_files() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))  # the sample's frames are more

    out = tmp_path / "bag"
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "export", str(SAMPLE), "--format", "ros2-bag", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=small_files,
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr[-2000:]
    assert "cannot write the bag" in run.stderr and "nothing was left behind" in run.stderr
    assert not out.exists()


def test_the_cli_bag_carries_the_mounting_on_tf_static_in_the_frame_its_images_are_stamped_with(tmp_path):
    """``export --format ros2-bag --workcell F``: the camera's mounting on /tf_static (transient local, as tf2's
    static broadcaster offers it) under the name the images and camera_info carry."""
    from rosbags.highlevel import AnyReader
    from rosbags.interfaces import QosDurability
    from rosbags.typesys import Stores, get_typestore
    from scipy.spatial.transform import Rotation

    from calib_core.bags.bag_export import TF_STATIC_TOPIC
    from calib_core.frames import concat, invert
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    out = tmp_path / "bag"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "export",
            str(SAMPLE),
            "--format",
            "ros2-bag",
            "--out",
            str(out),
            "--workcell",
            str(DEFAULT_WORKCELL),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    cell = load_workcell(DEFAULT_WORKCELL)
    robot = cell.load_robot()
    q = np.array(cell.home_joints_deg, float)
    camera2flange = concat(invert(robot.fk(q, "flange")), robot.fk(q, "camera"))  # the mounting, another way
    with AnyReader([out], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        tf = next(c for c in reader.connections if c.topic == TF_STATIC_TOPIC)
        assert (
            tf.msgtype == "tf2_msgs/msg/TFMessage"
            and tf.ext.offered_qos_profiles[0].durability is QosDurability.TRANSIENT_LOCAL
        )
        (message,) = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages([tf])]
        image = next(
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages([c for c in reader.connections if c.topic == IMAGE_TOPIC])
        )
    (stamped,) = message.transforms
    assert (
        stamped.child_frame_id == image.header.frame_id == "videocal_camera_optical_frame"
        and stamped.header.frame_id == robot.roles["flange"]
    )
    t, r = stamped.transform.translation, stamped.transform.rotation
    np.testing.assert_allclose(np.array([t.x, t.y, t.z]) * 1000.0, camera2flange[:3, 3], atol=1e-6)
    np.testing.assert_allclose(Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix(), camera2flange[:3, :3], atol=1e-9)
