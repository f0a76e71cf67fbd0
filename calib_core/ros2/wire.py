"""ROS 2's naming and QoS on DDS, as ``rmw_cyclonedds_cpp`` puts them.

A topic ``/joint_states`` is the DDS topic ``rt/joint_states``; the domain is ``ROS_DOMAIN_ID`` (0 when
unset). QoS: ROS 2's default profile (reliable, volatile, keep last 10), its sensor-data profile (best
effort, volatile, keep last 5) and tf2's static profile (reliable, transient local, keep last 1).
"""

from __future__ import annotations

import os
import re

from cyclonedds.core import Policy, Qos
from cyclonedds.util import duration

from calib_core.errors import VideocalError

_NAME = re.compile(r"^/?[A-Za-z_~][A-Za-z0-9_/~]*$")


class Ros2NameError(VideocalError, ValueError):
    """Not a valid ROS 2 topic name or domain id."""


def dds_topic(ros_topic: str) -> str:
    """``/ns/name`` -> ``rt/ns/name`` (a relative name is taken in the root namespace)."""
    if not _NAME.match(ros_topic) or "//" in ros_topic or ros_topic.endswith("/"):
        raise Ros2NameError(
            f"{ros_topic!r} is not a ROS 2 topic name (letters, digits, _ and /, not starting with a digit)"
        )
    return "rt/" + ros_topic.lstrip("/")


def domain_id(given: int | str | None = None) -> int:
    """The DDS domain: ``given``, else ``ROS_DOMAIN_ID``, else 0; ROS 2 allows 0..232."""
    raw = given if given is not None else os.environ.get("ROS_DOMAIN_ID", "0") or "0"
    try:
        value = int(raw)
    except (TypeError, ValueError):
        raise Ros2NameError(f"ROS_DOMAIN_ID must be a number 0..232, got {raw!r}") from None
    if not 0 <= value <= 232:
        raise Ros2NameError(f"ROS_DOMAIN_ID must lie in 0..232, got {value}")
    return value


def default_qos(depth: int = 10) -> Qos:
    """ROS 2's default (``rmw_qos_profile_default``)."""
    return Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(depth),
    )


def sensor_qos(depth: int = 5) -> Qos:
    """ROS 2's sensor data profile (``rmw_qos_profile_sensor_data``)."""
    return Qos(Policy.Reliability.BestEffort, Policy.Durability.Volatile, Policy.History.KeepLast(depth))


def static_tf_qos() -> Qos:
    """tf2_ros's ``/tf_static``: a late subscriber still receives the latest message."""
    return Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.TransientLocal,
        Policy.History.KeepLast(1),
    )
