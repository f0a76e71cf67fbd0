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
                    msg = T[kind](
                        header=header, height=h, width=w, encoding="mono8", is_bigendian=0, step=w, data=image.ravel()
                    )
                writer.write(connection, t_ns, ts.serialize_cdr(msg, kind))
        if camera_info:
            kind = "sensor_msgs/msg/CameraInfo"
            connection = writer.add_connection("/camera/camera_info", kind, typestore=ts)
            roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
            info = T[kind](
                header=Header(stamp=Time(sec=1_700_000_000, nanosec=0), frame_id="camera"),
                height=480,
                width=640,
                distortion_model="plumb_bob",
                d=np.array([0.1, -0.2, 0.0, 0.0, 0.0]),
                k=np.array([530.0, 0, 320, 0, 530.0, 240, 0, 0, 1]),
                r=np.eye(3).ravel(),
                p=np.zeros(12),
                binning_x=0,
                binning_y=0,
                roi=roi,
            )
            writer.write(connection, 1_700_000_000_000_000_000, ts.serialize_cdr(info, kind))
        kind = "sensor_msgs/msg/JointState"
        connection = writer.add_connection("/joint_states", kind, typestore=ts)
        js = T[kind](
            header=Header(stamp=Time(sec=1_700_000_000, nanosec=0), frame_id=""),
            name=["a"],
            position=np.array([0.1]),
            velocity=np.array([], float),
            effort=np.array([], float),
        )
        writer.write(connection, 1_700_000_000_000_000_000, ts.serialize_cdr(js, kind))
    return folder


def hold_and_move(poses, t0_ns: int, hold_s: float = 1.0, move_s: float = 1.0, rate_hz: float = 100.0):
    """A recorded session's timeline: the arm holds each of ``poses`` (joint vectors) for ``hold_s``, then moves
    to the next in ``move_s``, sampled at ``rate_hz``. Returns ``(track, shots, moving)``: the joint samples
    ``(t_ns, q)``, a frame's ``(t_ns, q)`` mid-hold and mid-move, and how many of those were taken moving."""
    track, shots, t = [], [], t0_ns
    for k, q in enumerate(poses):
        q = np.asarray(q, float)
        for j in range(int(hold_s * rate_hz)):
            track.append((t + int(j / rate_hz * 1e9), q))
        shots.append((t + int(hold_s / 2 * 1e9), q))
        t += int(hold_s * 1e9)
        if k + 1 < len(poses):
            nxt = np.asarray(poses[k + 1], float)
            for j in range(int(move_s * rate_hz)):
                f = j / (move_s * rate_hz)
                track.append((t + int(j / rate_hz * 1e9), (1 - f) * q + f * nxt))
            shots.append((t + int(move_s / 2 * 1e9), 0.5 * (q + nxt)))
            t += int(move_s * 1e9)
    return track, shots, len(poses) - 1


FOREARM2FLANGE_MM = (120.0, -35.0, 410.0)
"""Where the bag's made-up ``forearm`` frame stands from the flange (tf2 walks the chain through it)."""


def write_arm_bag(
    folder: Path,
    intrinsics,
    robot,
    shots: list[tuple[int, np.ndarray]],
    track: list[tuple[int, np.ndarray]],
    *,
    camera_info: bool = True,
    joint_states: bool = True,
    tf: bool = False,
) -> Path:
    """A ROS 2 bag (MCAP) as a ROS 2 system records a gripper camera and its arm: ``shots`` (``(t_ns, RGB image)``)
    as JPEG CompressedImage on ``/camera/image_raw/compressed`` (recorded 30 ms after the stamp), ``track``
    (``(t_ns, model joints)``) as JointState on ``/joint_states`` in SI units with a gripper joint beside the
    arm's (recorded 2 ms after), and ``intrinsics`` as one CameraInfo. With ``tf`` the arm is on ``/tf`` as a
    driver publishes it: ``base_link -> forearm`` streamed, ``forearm -> flange`` and ``world -> base_link`` on
    ``/tf_static`` (metres, quaternions)."""
    import math

    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    stamp = lambda t: Time(sec=t // 10**9, nanosec=t % 10**9)  # noqa: E731
    t0 = min(t for t, _ in track)
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        images = writer.add_connection("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage", typestore=ts)
        joints = writer.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=ts)
        if camera_info:
            info = writer.add_connection("/camera/camera_info", "sensor_msgs/msg/CameraInfo", typestore=ts)
            roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
            i = intrinsics
            msg = T["sensor_msgs/msg/CameraInfo"](
                header=Header(stamp=stamp(t0), frame_id="camera_optical_frame"),
                height=i.height,
                width=i.width,
                distortion_model="plumb_bob",
                d=np.array(i.distortion, float),
                k=np.array([i.fu, 0, i.cx, 0, i.fv, i.cy, 0, 0, 1.0]),
                r=np.eye(3).ravel(),
                p=np.zeros(12),
                binning_x=0,
                binning_y=0,
                roi=roi,
            )
            writer.write(info, t0, ts.serialize_cdr(msg, "sensor_msgs/msg/CameraInfo"))
        names = list(robot.joint_names) + [
            "gripper_finger"
        ]  # the gripper's joint in the same message, as many drivers do
        si = np.array([math.pi / 180.0 if u == "deg" else 1e-3 for u in robot.joint_units])
        if tf:
            _write_tf(writer, ts, robot, track)
        for t, q in track if joint_states else []:
            msg = T["sensor_msgs/msg/JointState"](
                header=Header(stamp=stamp(t), frame_id=""),
                name=names,
                position=np.append(q * si, 0.01),
                velocity=np.array([], float),
                effort=np.array([], float),
            )
            writer.write(joints, t + 2_000_000, ts.serialize_cdr(msg, "sensor_msgs/msg/JointState"))
        for t, image in shots:
            ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 95])
            msg = T["sensor_msgs/msg/CompressedImage"](
                header=Header(stamp=stamp(t), frame_id="camera_optical_frame"),
                format="jpeg",
                data=np.frombuffer(jpeg.tobytes(), np.uint8),
            )
            writer.write(images, t + 30_000_000, ts.serialize_cdr(msg, "sensor_msgs/msg/CompressedImage"))
    return folder


def _write_tf(writer, ts, robot, track) -> None:
    from scipy.spatial.transform import Rotation

    from calib_core.frames import concat, invert, make_transform

    T = ts.types
    kind = "tf2_msgs/msg/TFMessage"
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]

    def stamped(t_ns, parent, child, child2parent):
        x, y, z = np.asarray(child2parent)[:3, 3] / 1000.0
        qx, qy, qz, qw = Rotation.from_matrix(np.asarray(child2parent)[:3, :3]).as_quat()
        return T["geometry_msgs/msg/TransformStamped"](
            header=Header(stamp=Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9), frame_id=parent),
            child_frame_id=child,
            transform=T["geometry_msgs/msg/Transform"](
                translation=T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
                rotation=T["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
            ),
        )

    flange2forearm = make_transform(
        Rotation.from_euler("xyz", [20, -35, 50], degrees=True).as_matrix(), FOREARM2FLANGE_MM
    )
    t0 = min(t for t, _ in track)
    static = writer.add_connection("/tf_static", kind, typestore=ts)
    latched = [
        stamped(t0, "forearm", "flange", flange2forearm),
        stamped(t0, "world", "base_link", make_transform(np.eye(3), (0.0, 0.0, 800.0))),
    ]
    writer.write(static, t0, ts.serialize_cdr(T[kind](transforms=latched), kind))
    dynamic = writer.add_connection("/tf", kind, typestore=ts)
    for t, q in track:
        forearm2base = concat(invert(flange2forearm), robot.fk(q, "flange"))
        writer.write(
            dynamic,
            t + 1_000_000,
            ts.serialize_cdr(T[kind](transforms=[stamped(t, "base_link", "forearm", forearm2base)]), kind),
        )
