"""The ROS 2 camera connector: ``ros2:///camera/image_raw`` (``sensor_msgs/Image``) or
``ros2:///camera/image_raw/compressed`` (``sensor_msgs/CompressedImage``, image_transport's name), with the
camera's ``sensor_msgs/CameraInfo`` from the sibling ``camera_info`` topic.

A frame's ``t_source_s`` is its header stamp (s since the epoch, the camera driver's clock); its ``t_host_s``
is that instant on the host's monotonic clock (the stamp's age subtracted from the arrival, never later than
the arrival), so picks are bound to the joints when the image was taken, not when it arrived. The reader is best
effort (it hears both best-effort and reliable publishers, as ``rclcpp``'s sensor-data subscriptions do) and keeps
only the newest image: a slow window skips frames, it never queues them. A camera that goes quiet gives
:class:`~calib_core.connectors.frame.FrameTimeout` (the pane keeps waiting and says so); when it comes back, so do
frames.
"""

from __future__ import annotations

import threading
import time
from urllib.parse import parse_qs

from calib_core.connectors.urls import split_url
from calib_core.connectors.frame import Frame, FrameSource, FrameTimeout, VideoSourceError

_OPTIONS = {"domain", "timeout_s"}


class Ros2ImageSource(FrameSource):
    def __init__(self, spec: str, options: dict | None = None):
        from calib_core.ros2.wire import Ros2NameError, dds_topic, domain_id

        parts = split_url(spec, VideoSourceError)
        if parts.netloc:
            raise VideoSourceError(
                f"{spec!r}: a ros2 URL has no host (ros2:///camera/image_raw); the domain is ROS_DOMAIN_ID or ?domain=N"
            )
        merged = dict(options or {})
        merged.update({k: v[-1] for k, v in parse_qs(parts.query).items()})
        unknown = set(merged) - _OPTIONS
        if unknown:
            raise VideoSourceError(
                f"{spec!r}: unknown option(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_OPTIONS))}"
            )
        topic = parts.path or "/camera/image_raw"
        self.compressed = topic.endswith("/compressed")
        base = topic[: -len("/compressed")] if self.compressed else topic
        info_topic = base.rsplit("/", 1)[0] + "/camera_info"
        try:
            self.domain = domain_id(merged.get("domain"))
            self._topic, self._info_topic = dds_topic(topic), dds_topic(info_topic)
            self.timeout_s = float(merged.get("timeout_s", 2.0))
        except (Ros2NameError, ValueError) as exc:
            raise VideoSourceError(f"{spec!r}: {exc}") from None
        self.description = f"ROS 2 camera {topic}"
        self.topic = topic
        self.camera_info = None
        """The newest ``sensor_msgs/CameraInfo`` heard (its ``k``, ``d``, ``distortion_model``), or None."""
        self._index = 0
        self._newest = None
        self._ready = threading.Condition()
        self._stop = threading.Event()
        self._open()

    def _open(self) -> None:
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from calib_core.ros2 import messages as msg
        from calib_core.ros2.participant import participant
        from calib_core.ros2.taker import Taker
        from calib_core.ros2.wire import default_qos, sensor_qos

        dp = participant(self.domain)
        kind = msg.CompressedImage if self.compressed else msg.Image
        self._taker = Taker(DataReader(dp, Topic(dp, self._topic, kind), qos=sensor_qos(1)))
        self._info = Taker(DataReader(dp, Topic(dp, self._info_topic, msg.CameraInfo), qos=default_qos(1)))
        self._thread = threading.Thread(target=self._listen, name=f"ros2 camera {self.topic}", daemon=True)
        self._thread.start()

    def _listen(self) -> None:
        while not self._stop.is_set():
            try:
                images = self._taker.take(4, 0.05)
                infos = self._info.take(4, 0.0) if images or self.camera_info is None else []
            except Exception:  # a DDS hiccup: the next round tries again
                time.sleep(0.05)
                continue
            if infos:
                self.camera_info = infos[-1]
            if images:
                with self._ready:
                    self._newest = (images[-1], time.monotonic(), time.time())
                    self._ready.notify_all()

    @property
    def fps(self) -> float:
        return 0.0  # as fast as the camera sends

    def read(self) -> Frame:
        from calib_core.ros2.image_decoding import compressed_to_rgb, image_to_rgb

        with self._ready:
            if not self._ready.wait_for(lambda: self._newest is not None or self._stop.is_set(), self.timeout_s):
                raise FrameTimeout(
                    f"{self.description}: no image for {self.timeout_s:g} s (waiting for it; check the camera driver "
                    f"and ROS_DOMAIN_ID={self.domain})"
                )
            if self._newest is None:
                raise VideoSourceError(f"{self.description}: closed")
            message, t_arrival_host, t_arrival_epoch = self._newest
            self._newest = None
        rgb = (
            compressed_to_rgb(message, self.description) if self.compressed else image_to_rgb(message, self.description)
        )
        stamp_s = message.header.stamp.ns() / 1e9
        age_s = t_arrival_epoch - stamp_s
        # However old the frame, its stamp dates it (a late frame must never pass for a new one); a zero stamp
        # or one from a clock ahead of ours cannot, and then its arrival does.
        t_host = t_arrival_host - age_s if age_s >= 0.0 and stamp_s > 0 else t_arrival_host
        stamp_ns = message.header.stamp.ns()
        frame = Frame(rgb, self._index, t_host, stamp_s if stamp_s > 0 else None, stamp_ns if stamp_ns > 0 else None)
        self._index += 1
        return frame

    def close(self) -> None:
        self._stop.set()
        with self._ready:
            self._ready.notify_all()
        if getattr(self, "_thread", None) is not None:
            self._thread.join(timeout=1.0)
            if not self._thread.is_alive():
                self._taker.close()
                self._info.close()


def open_ros2_camera(spec: str, options: dict) -> Ros2ImageSource:
    """Entry point of ``videocal.cameras`` for ``ros2://``."""
    return Ros2ImageSource(spec, options)
