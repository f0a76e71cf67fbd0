"""Bags for the tests, written by ``rosbags`` (the writer ROS 2 users' Python tools use), of third-party photos."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

OPENCV = Path(__file__).parents[2] / "data" / "third_party" / "opencv_samples"


def chessboard_photos() -> list[np.ndarray]:
    """OpenCV's chessboard photos (left01..left14, 640 x 480, grey)."""
    return [cv2.imread(str(p), cv2.IMREAD_GRAYSCALE) for p in sorted(OPENCV.glob("left*.jpg"))]


def write_bag(folder: Path, storage: str, topics: dict[str, list], camera_info: bool = True) -> Path:
    """A ROS 2 bag at ``folder``: ``topics`` maps a topic to grey images (``raw`` mono8 Image) or JPEG bytes
    (CompressedImage, for a topic ending in ``/compressed``); a CameraInfo and a JointState go in too."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    with Writer(folder, version=9, storage_plugin=plugin) as writer:
        for topic, images in topics.items():
            compressed = topic.endswith("/compressed")
            kind = "sensor_msgs/msg/CompressedImage" if compressed else "sensor_msgs/msg/Image"
            connection = writer.add_connection(topic, kind, typestore=ts)
            for k, image in enumerate(images):
                t_ns = 1_700_000_000_000_000_000 + k * 500_000_000
                header = Header(stamp=Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9), frame_id="camera")
                if compressed:
                    msg = T[kind](header=header, format="jpeg", data=np.frombuffer(image, np.uint8))
                else:
                    h, w = image.shape
                    msg = T[kind](header=header, height=h, width=w, encoding="mono8", is_bigendian=0, step=w, data=image.ravel())
                writer.write(connection, t_ns, ts.serialize_cdr(msg, kind))
        if camera_info:
            kind = "sensor_msgs/msg/CameraInfo"
            connection = writer.add_connection("/camera/camera_info", kind, typestore=ts)
            roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
            info = T[kind](header=Header(stamp=Time(sec=1_700_000_000, nanosec=0), frame_id="camera"), height=480, width=640,
                           distortion_model="plumb_bob", d=np.array([0.1, -0.2, 0.0, 0.0, 0.0]),
                           k=np.array([530.0, 0, 320, 0, 530.0, 240, 0, 0, 1]), r=np.eye(3).ravel(), p=np.zeros(12), binning_x=0, binning_y=0, roi=roi)
            writer.write(connection, 1_700_000_000_000_000_000, ts.serialize_cdr(info, kind))
        kind = "sensor_msgs/msg/JointState"
        connection = writer.add_connection("/joint_states", kind, typestore=ts)
        js = T[kind](header=Header(stamp=Time(sec=1_700_000_000, nanosec=0), frame_id=""), name=["a"], position=np.array([0.1]),
                     velocity=np.array([], float), effort=np.array([], float))
        writer.write(connection, 1_700_000_000_000_000_000, ts.serialize_cdr(js, kind))
    return folder
