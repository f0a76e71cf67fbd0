"""``/tf_static`` as tf2's static broadcaster writes it: one ``tf2_msgs/TFMessage`` holding every static
transform, reliable and transient local (keep last 1), so a late subscriber still gets all of them."""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.ros2 import messages as msg


def transform_stamped(parent: str, child: str, child2parent_mm: np.ndarray, stamp_ns: int) -> msg.TransformStamped:
    """``child2parent_mm`` (4, 4), mm: the child frame's pose in the parent's; ROS wants m and a quaternion."""
    pose = np.asarray(child2parent_mm, dtype=float)
    x, y, z, w = Rotation.from_matrix(pose[:3, :3]).as_quat()
    t = pose[:3, 3] / 1000.0
    return msg.TransformStamped(
        msg.Header(msg.Time.of_ns(stamp_ns), parent),
        child,
        msg.Transform(msg.Vector3(*map(float, t)), msg.Quaternion(float(x), float(y), float(z), float(w))),
    )


class StaticTransformBroadcaster:
    """Publishes ``{child: (parent, child2parent_mm)}`` on ``/tf_static`` of ``domain``, the whole set each time."""

    def __init__(self, domain: int):
        from cyclonedds.pub import DataWriter
        from cyclonedds.topic import Topic

        from calib_core.ros2.participant import participant
        from calib_core.ros2.wire import static_tf_qos

        dp = participant(domain)
        self._writer = DataWriter(dp, Topic(dp, "rt/tf_static", msg.TFMessage), qos=static_tf_qos())
        self.transforms: dict[str, msg.TransformStamped] = {}

    def publish(self, transforms: list[tuple[str, str, np.ndarray]]) -> None:
        """Replace the transforms of these children and publish the whole set."""
        stamp = time.time_ns()
        for parent, child, pose in transforms:
            self.transforms[child] = transform_stamped(parent, child, pose, stamp)
        self._writer.write(msg.TFMessage(list(self.transforms.values())))
