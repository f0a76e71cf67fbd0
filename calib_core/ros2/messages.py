"""ROS 2 message types as DDS sees them: each ``pkg/msg/Type`` is the IDL struct ``pkg::msg::dds_::Type_``
with ROS 2's field order and types (``rosidl`` maps ``float64[]`` to a sequence, ``float64[9]`` to an
array, ``string`` to a string). Only the types videocal reads or writes."""

# No ``from __future__ import annotations``: cyclonedds reads these annotations as types.
from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int32, sequence, uint8, uint32


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0

    @classmethod
    def of_ns(cls, t_ns: int) -> "Time":
        return cls(int(t_ns // 1_000_000_000), int(t_ns % 1_000_000_000))

    def ns(self) -> int:
        return int(self.sec) * 1_000_000_000 + int(self.nanosec)


@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: int32 = 0
    nanosec: uint32 = 0

    @classmethod
    def of_s(cls, seconds: float) -> "Duration":
        ns = int(round(seconds * 1e9))
        return cls(int(ns // 1_000_000_000), int(ns % 1_000_000_000))

    def seconds(self) -> float:
        return int(self.sec) + int(self.nanosec) * 1e-9


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    """Positions in rad (revolute) or m (prismatic), by joint name."""

    header: Header = field(default_factory=Header)
    name: sequence[str] = field(default_factory=list)
    position: sequence[float64] = field(default_factory=list)
    velocity: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)


@dataclass
class JointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectoryPoint_"):
    positions: sequence[float64] = field(default_factory=list)
    velocities: sequence[float64] = field(default_factory=list)
    accelerations: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class JointTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectory_"):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    points: sequence[JointTrajectoryPoint] = field(default_factory=list)


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    """``header.frame_id``: the parent frame; ``child_frame_id``: the frame placed; translation in m."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@dataclass
class TFMessage(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    transforms: sequence[TransformStamped] = field(default_factory=list)


@dataclass
class Image(IdlStruct, typename="sensor_msgs::msg::dds_::Image_"):
    header: Header = field(default_factory=Header)
    height: uint32 = 0
    width: uint32 = 0
    encoding: str = ""
    is_bigendian: uint8 = 0
    step: uint32 = 0
    data: sequence[uint8] = field(default_factory=bytes)


@dataclass
class CompressedImage(IdlStruct, typename="sensor_msgs::msg::dds_::CompressedImage_"):
    header: Header = field(default_factory=Header)
    format: str = ""
    data: sequence[uint8] = field(default_factory=bytes)


@dataclass
class RegionOfInterest(IdlStruct, typename="sensor_msgs::msg::dds_::RegionOfInterest_"):
    x_offset: uint32 = 0
    y_offset: uint32 = 0
    height: uint32 = 0
    width: uint32 = 0
    do_rectify: bool = False


@dataclass
class CameraInfo(IdlStruct, typename="sensor_msgs::msg::dds_::CameraInfo_"):
    header: Header = field(default_factory=Header)
    height: uint32 = 0
    width: uint32 = 0
    distortion_model: str = ""
    d: sequence[float64] = field(default_factory=list)
    k: array[float64, 9] = field(default_factory=lambda: [0.0] * 9)
    r: array[float64, 9] = field(default_factory=lambda: [0.0] * 9)
    p: array[float64, 12] = field(default_factory=lambda: [0.0] * 12)
    binning_x: uint32 = 0
    binning_y: uint32 = 0
    roi: RegionOfInterest = field(default_factory=RegionOfInterest)


def _octets_in_one_copy(message_type, member: str) -> None:
    """Serialise ``sequence<uint8>`` ``member`` from and to ``bytes`` in one copy.

    cyclonedds packs a ``sequence[uint8]`` element by element (0.6 s for a 1280 x 960 RGB image, and a list of
    3.7 million ints on reading). On the wire a ``sequence<uint8>`` is a 4-aligned uint32 length and the octets,
    exactly what cyclonedds's own ``bytes`` machine writes; the type object (what peers see) stays
    ``sequence<uint8>``. Checked against a reader and writer declared with plain ``sequence[uint8]``
    (tests/core/ros2/test_image_source.py)."""
    from cyclonedds.idl._machinery import BytesMachine

    message_type.__idl__.populate()
    for machine in (message_type.__idl__.v1_machine, message_type.__idl__.v2_machine):
        machine.members_machines[member] = BytesMachine()


_octets_in_one_copy(Image, "data")
_octets_in_one_copy(CompressedImage, "data")
