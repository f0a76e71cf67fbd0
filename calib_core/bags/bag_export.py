"""A videocal recording as a ROS 2 bag: what ``ros2 bag info``/``play`` and rosbags-based tools read, beside
the Foxglove MCAP the recorder writes. Written with ``rosbags`` (MCAP storage, ROS 2 Humble's message definitions):

- ``/camera/image_raw/compressed``: ``sensor_msgs/CompressedImage`` (JPEG), each frame stamped with its time in the
  recording (the H.264 track decoded frame by frame);
- ``/joint_states``: ``sensor_msgs/JointState`` in the robot's URDF joint names, **radians and metres** (a recording
  holds degrees and mm: the workcell's robot says which joint is prismatic);
- ``/camera/camera_info``: ``sensor_msgs/CameraInfo`` from the recording's camera, with every image at its stamp;
- ``/tf_static``: the camera's mounting (``tf2_msgs/TFMessage``, transient local as tf2's static broadcaster offers it),
  the camera's frame the one the images and camera_info are stamped with (:mod:`calib_core.ros2.frame_names`).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import cv2
import numpy as np

from calib_core.errors import FileFormatError, FileWriteError

IMAGE_TOPIC = "/camera/image_raw/compressed"
JOINT_TOPIC = "/joint_states"
INFO_TOPIC = "/camera/camera_info"
TF_STATIC_TOPIC = "/tf_static"


def cell_mounting(workcell) -> tuple[str, str, np.ndarray]:
    """``(parent, child, camera2parent)`` (4, 4) mm: the camera's mounting in ``workcell`` (a loaded workcell), named
    as every ROS output names it (:func:`~calib_core.ros2.frame_names.camera_frames`)."""
    from calib_core.frames import concat, invert
    from calib_core.ros2.frame_names import camera_frames

    robot = workcell.load_robot()
    parent, child = camera_frames(workcell, flange_frame=robot.roles.get("flange"))
    q = np.array(workcell.home_joints_deg, dtype=float)
    return parent, child, concat(invert(robot.fk(q, parent)), robot.fk(q, "camera"))


def _stamp(T, t_ns: int):
    return T["builtin_interfaces/msg/Time"](sec=t_ns // 10**9, nanosec=t_ns % 10**9)


def recording_to_bag(
    recording: str | Path,
    out: str | Path,
    *,
    joint_units: list[str] | None = None,
    mounting: tuple[str, str, np.ndarray] | None = None,
) -> dict:
    """Write the recording at ``recording`` as a ROS 2 bag folder ``out`` (which must not exist). ``joint_units``: each
    joint's unit (``deg``/``mm``) in the recording's joint order (default: the recording's workcell's robot).
    ``mounting``: ``(parent, child, camera2parent)`` (:func:`cell_mounting`) put on ``/tf_static``, its ``child`` the
    images' frame (default: none on /tf_static, the images in ``videocal_camera_optical_frame``).
    Returns what was written per topic. :class:`FileFormatError` names the file: no recording, no frames and no
    joints, joints whose units cannot be told, or an ``out`` that exists."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    from calib_core.recording.frame_track import FrameTrack
    from calib_core.recording.reader import read_recording
    from calib_core.recording.schemas import JOINTS_TOPIC, SETUP_TOPIC

    recording, out = Path(recording), Path(out)
    if out.exists():
        raise FileFormatError(out, "exists already: a bag is written into a new folder (nothing was replaced)")
    contents = read_recording(recording)
    setup = (contents.topic(SETUP_TOPIC) or [None])[-1]
    setup = setup.payload if setup is not None else {}
    joints = contents.topic(JOINTS_TOPIC)
    track = FrameTrack(contents)
    if not joints and not len(track):
        raise FileFormatError(recording, "the recording holds no camera frames and no joint samples: nothing to write")
    names = list(setup.get("joint_names") or [])
    n = len(joints[0].payload["joints_deg"]) if joints else 0
    if joints and len(names) != n:
        names = [f"joint_{k + 1}" for k in range(n)]
    if joints and joint_units is None:
        joint_units = _units_from_workcell(recording, setup.get("workcell"), n)
    intrinsics = setup.get("intrinsics") or None

    ts = get_typestore(Stores.ROS2_HUMBLE)
    T = ts.types
    counts = {IMAGE_TOPIC: 0, JOINT_TOPIC: 0, INFO_TOPIC: 0}
    from calib_core.ros2.frame_names import DEFAULT_CAMERA_FRAME

    camera_frame = DEFAULT_CAMERA_FRAME if mounting is None else mounting[1]
    first_ns = min([m.log_time_ns for m in track.messages[:1]] + [m.log_time_ns for m in joints[:1]])
    try:
        _write(
            Writer(out, version=9, storage_plugin=StoragePlugin.MCAP),
            ts,
            T,
            track,
            joints,
            names,
            joint_units,
            intrinsics,
            camera_frame,
            counts,
            mounting,
            first_ns,
        )
    except BaseException as exc:
        shutil.rmtree(out, ignore_errors=True)  # no half-written bag left behind
        if isinstance(exc, OSError) or type(exc).__name__ == "WriterError":  # a full disk, a read-only folder
            cause = exc.__cause__ if isinstance(exc.__cause__, OSError) else exc
            raise FileWriteError(
                out, f"cannot write the bag ({getattr(cause, 'strerror', None) or cause}); nothing was left behind"
            ) from None
        raise
    return counts


def _write(
    writer,
    ts,
    T,
    track,
    joints,
    names,
    joint_units,
    intrinsics,
    camera_frame: str,
    counts: dict,
    mounting,
    first_ns: int,
) -> None:
    with writer:
        if mounting is not None:
            _write_mounting(writer, ts, T, mounting, first_ns)
            counts[TF_STATIC_TOPIC] = 1
        if len(track):
            images = writer.add_connection(IMAGE_TOPIC, "sensor_msgs/msg/CompressedImage", typestore=ts)
            info = _camera_info(T, intrinsics, camera_frame) if intrinsics else None
            infos = (
                writer.add_connection(INFO_TOPIC, "sensor_msgs/msg/CameraInfo", typestore=ts)
                if info is not None
                else None
            )
            for k, message in enumerate(track.messages):
                rgb = track.image(k)
                if rgb is None:
                    continue  # before the first keyframe of a cut recording: no picture to give
                ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 92])
                header = T["std_msgs/msg/Header"](stamp=_stamp(T, message.log_time_ns), frame_id=camera_frame)
                msg = T["sensor_msgs/msg/CompressedImage"](
                    header=header, format="jpeg", data=np.frombuffer(jpeg.tobytes(), np.uint8)
                )
                writer.write(images, message.log_time_ns, ts.serialize_cdr(msg, "sensor_msgs/msg/CompressedImage"))
                counts[IMAGE_TOPIC] += 1
                if info is not None:
                    # one CameraInfo with every image, at its stamp: image_proc and most consumers pair them by stamp
                    info.header = header
                    writer.write(infos, message.log_time_ns, ts.serialize_cdr(info, "sensor_msgs/msg/CameraInfo"))
                    counts[INFO_TOPIC] += 1
        if joints:
            connection = writer.add_connection(JOINT_TOPIC, "sensor_msgs/msg/JointState", typestore=ts)
            per_si = np.array([math.pi / 180.0 if u == "deg" else 1e-3 for u in joint_units])
            for message in joints:
                q = np.asarray(message.payload["joints_deg"], float) * per_si
                header = T["std_msgs/msg/Header"](stamp=_stamp(T, message.log_time_ns), frame_id="")
                js = T["sensor_msgs/msg/JointState"](
                    header=header, name=names, position=q, velocity=np.array([], float), effort=np.array([], float)
                )
                writer.write(connection, message.log_time_ns, ts.serialize_cdr(js, "sensor_msgs/msg/JointState"))
                counts[JOINT_TOPIC] += 1


def _write_mounting(writer, ts, T, mounting, t_ns: int) -> None:
    """The camera's mounting on /tf_static at the bag's first stamp, offered transient local (tf2's static
    broadcaster's QoS: a player hands it to subscribers that join later)."""
    from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
    from scipy.spatial.transform import Rotation

    parent, child, camera2parent = mounting
    never = QosTime(0x7FFFFFFF, 0xFFFFFFFF)
    qos = Qos(
        QosHistory.KEEP_LAST,
        1,
        QosReliability.RELIABLE,
        QosDurability.TRANSIENT_LOCAL,
        never,
        never,
        QosLiveliness.AUTOMATIC,
        never,
        False,
    )
    connection = writer.add_connection(
        TF_STATIC_TOPIC, "tf2_msgs/msg/TFMessage", typestore=ts, offered_qos_profiles=[qos]
    )
    x, y, z = (float(v) / 1000.0 for v in camera2parent[:3, 3])
    qx, qy, qz, qw = Rotation.from_matrix(camera2parent[:3, :3]).as_quat()
    transform = T["geometry_msgs/msg/Transform"](
        translation=T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
        rotation=T["geometry_msgs/msg/Quaternion"](x=float(qx), y=float(qy), z=float(qz), w=float(qw)),
    )
    stamped = T["geometry_msgs/msg/TransformStamped"](
        header=T["std_msgs/msg/Header"](stamp=_stamp(T, t_ns), frame_id=parent),
        child_frame_id=child,
        transform=transform,
    )
    message = T["tf2_msgs/msg/TFMessage"](transforms=[stamped])
    writer.write(connection, t_ns, ts.serialize_cdr(message, "tf2_msgs/msg/TFMessage"))


def _units_from_workcell(recording: Path, workcell: str | None, n: int) -> list[str]:
    """Each joint's unit from the robot of the workcell the recording was made with."""
    from calib_core.workcell import load_workcell

    if not workcell or not Path(workcell).is_file():
        raise FileFormatError(
            recording,
            f"the joints' units (deg or mm) come from the recording's workcell, {workcell or 'not named'}, which is "
            "not there: "
            "give --workcell",
        )
    units = list(load_workcell(workcell).load_robot().joint_units)
    if len(units) != n:
        raise FileFormatError(
            recording,
            f"the recording's samples have {n} joints, the workcell's robot {len(units)}: another cell's recording?",
        )
    return units


def _camera_info(T, intrinsics: dict, camera_frame: str):
    """The recording's camera as a ``sensor_msgs/CameraInfo`` (its header set per image)."""
    fu, fv, cx, cy = (float(intrinsics[k]) for k in ("fu", "fv", "cx", "cy"))
    d = [float(v) for v in intrinsics.get("distortion", [0.0] * 5)]
    roi = T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    header = T["std_msgs/msg/Header"](stamp=_stamp(T, 0), frame_id=camera_frame)
    return T["sensor_msgs/msg/CameraInfo"](
        header=header,
        height=int(intrinsics["height"]),
        width=int(intrinsics["width"]),
        distortion_model=str(intrinsics.get("distortion_model", "plumb_bob")),
        d=np.array(d, float),
        k=np.array([fu, 0, cx, 0, fv, cy, 0, 0, 1], float),
        r=np.eye(3).ravel(),
        p=np.array([fu, 0, cx, 0, 0, fv, cy, 0, 0, 0, 1, 0], float),
        binning_x=0,
        binning_y=0,
        roi=roi,
    )
