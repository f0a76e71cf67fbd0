"""ROS 2 bags written by rosbags, of OpenCV's chessboard photos, as a source of images: MCAP and sqlite3 storage,
a bag folder or its file, raw and compressed images, topic choice, and bags with nothing usable."""

import subprocess
import sys

import cv2
import numpy as np
import pytest

from calib_core.bags.bag_source import bag_camera_info, bag_images, bag_topics, choose_image_topic
from calib_core.errors import FileFormatError
from tests.core.bags.bag_writing import OPENCV, chessboard_photos, write_bag


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_images_come_back_exactly_from_either_storage(tmp_path, storage):
    photos = chessboard_photos()[:3]
    bag = write_bag(tmp_path / "bag", storage, {"/camera/image_raw": photos})
    got = list(bag_images(bag))
    assert [name for name, _ in got] == [f"t_{1_700_000_000_000_000_000 + k * 500_000_000}" for k in range(3)]
    assert all(np.array_equal(rgb[:, :, 0], photo) for (_, rgb), photo in zip(got, photos))
    storage_file = next(p for p in bag.iterdir() if p.suffix in (".mcap", ".db3"))
    assert len(list(bag_images(storage_file))) == 3  # the bag's file names the bag
    topic, info = bag_camera_info(bag)
    assert topic == "/camera/camera_info" and list(info.k)[:3] == [530.0, 0.0, 320.0]


def test_topic_choice_and_what_a_bag_without_images_says(tmp_path):
    photos = chessboard_photos()[:2]
    jpegs = [cv2.imencode(".jpg", p)[1].tobytes() for p in photos]
    bag = write_bag(tmp_path / "two", "mcap", {"/left/image_raw": photos, "/right/image_raw/compressed": jpegs})
    with pytest.raises(
        FileFormatError,
        match="several image topics: choose one with --topic: /left/image_raw .*/right/image_raw/compressed",
    ):
        choose_image_topic(bag)
    right = list(bag_images(bag, "/right/image_raw/compressed"))
    assert len(right) == 2 and np.abs(right[0][1][:, :, 0].astype(int) - photos[0]).mean() < 3  # JPEG
    with pytest.raises(FileFormatError, match="topic /joint_states holds sensor_msgs/msg/JointState, not images"):
        choose_image_topic(bag, "/joint_states")
    empty = write_bag(tmp_path / "none", "mcap", {})
    with pytest.raises(FileFormatError, match=r"no images in this bag \(it holds /camera/camera_info .*/joint_states"):
        list(bag_images(empty))
    assert [t.name for t in bag_topics(empty)] == ["/camera/camera_info", "/joint_states"]


def test_calibrate_intrinsics_from_a_bag_matches_the_photos_folder(tmp_path):
    bag = write_bag(tmp_path / "bag", "mcap", {"/camera/image_raw": chessboard_photos()})
    common = ["--board", "chessboard:9x6:25", "--json"]
    runs = {}
    for name, source in (("bag", bag), ("folder", OPENCV)):
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "app.cli.main",
                "calibrate-intrinsics",
                str(source),
                "--out",
                str(tmp_path / f"{name}.yaml"),
                *common,
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 0, done.stderr
        runs[name] = __import__("json").loads(done.stdout)
    assert runs["bag"]["views_used"] == runs["folder"]["views_used"] == 13
    for key in ("fu", "fv", "cx", "cy"):
        assert runs["bag"][key] == pytest.approx(runs["folder"][key], abs=1e-6)
    wrong = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-intrinsics",
            str(bag),
            "--topic",
            "/nope",
            "--out",
            str(tmp_path / "x.yaml"),
            *common,
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert (
        wrong.returncode == 2
        and "no topic /nope; image topics: /camera/image_raw (sensor_msgs/msg/Image, 13)" in wrong.stderr
    )


def test_a_bag_given_as_a_recording_is_refused_naming_what_it_holds(tmp_path):
    """`replay bag.mcap` said '0 solves' with exit 0; a bag folder said 'Is a directory'."""
    from mcap.writer import Writer

    bag = write_bag(tmp_path / "bag", "mcap", {"/camera/image_raw": chessboard_photos()[:1]})
    mcap_file = next(bag.glob("*.mcap"))
    header_only = tmp_path / "header_only.mcap"
    with header_only.open("wb") as f:
        writer = Writer(f)
        writer.start()
        writer.finish()
    for source, expected in (
        (mcap_file, "not a videocal recording: no videocal message (its topics: /camera/camera_info (cdr)"),
        (bag, "a ROS bag folder, not a videocal recording"),
        (header_only, "not a videocal recording: no videocal message (it holds no messages)"),
    ):
        run = subprocess.run(
            [sys.executable, "-m", "app.cli.main", "replay", str(source)], capture_output=True, text=True, timeout=120
        )
        assert run.returncode == 2 and expected in run.stderr and "Traceback" not in run.stderr, run.stderr
    recover = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "recover", str(header_only), str(tmp_path / "copy.mcap")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert recover.returncode == 2 and not (tmp_path / "copy.mcap").exists()  # no empty copy


def test_a_bag_whose_messages_are_not_cdr_is_one_error_naming_the_topic_and_message(tmp_path):
    """rosbags' own error escaped as a traceback from calibrate-intrinsics on such a bag."""
    import subprocess
    import sys

    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    from calib_core.bags.bag_source import bag_images
    from calib_core.errors import FileFormatError

    ts = get_typestore(Stores.ROS2_HUMBLE)
    folder = tmp_path / "garbage_bag"
    with Writer(folder, version=9) as writer:
        connection = writer.add_connection("/camera/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        writer.write(connection, 1_700_000_000_000_000_000, b"\x00\x01 not a CDR image at all")
    with pytest.raises(FileFormatError, match=r"/camera/image_raw message 0: not a sensor_msgs/msg/Image in CDR"):
        list(bag_images(folder))
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-intrinsics",
            str(folder),
            "--board",
            "chessboard:9x6:25",
            "--out",
            str(tmp_path / "camera.yaml"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert (
        run.returncode == 2 and "Traceback" not in run.stderr and "not a sensor_msgs/msg/Image in CDR" in run.stderr
    ), run.stderr[-2000:]
