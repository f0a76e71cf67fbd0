"""A ROS 2 bag on the replay timeline: its camera frames and the arm's joints at each, on the stamps' time axis.

The same questions as :class:`~calib_core.recording.playback.RecordingPlayback` answers for a videocal recording
(the frame shown at a time, the joints then), so the window replays a bag as it replays a recording: points are
picked on its frames and solved with the joints of each frame's stamp. A bag carries no pairs and no solves.

Times are seconds from the first image's header stamp; the joints are on their header stamps too (the robot's
clock), never the bag's record times. Frames are decoded when shown: only the index of the image messages (their
stamps and record times) is kept, so memory does not grow with the bag's length.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from calib_core.bags.bag_source import bag_intrinsics, choose_image_topic, messages, open_reader
from calib_core.bags.joint_track import JOINT_STATE, read_joint_track
from calib_core.errors import FileFormatError

_STAMP = struct.Struct("<iI")  # builtin_interfaces/Time, the first field of an Image's or CompressedImage's header


def _header_stamp_ns(raw: bytes, log_ns: int) -> int:
    """The header stamp of a serialized Image/CompressedImage (CDR: a 4-byte encapsulation header, then the header's
    stamp), read without deserializing the picture; the record time for a message that carries none."""
    little = len(raw) >= 2 and raw[1] in (1, 3)  # CDR_LE / PL_CDR_LE
    sec, nanosec = (_STAMP if little else struct.Struct(">iI")).unpack_from(raw, 4)
    stamp = sec * 1_000_000_000 + nanosec
    return stamp or log_ns


class BagFrames:
    """The image messages of one topic, indexed by stamp. ``times_s`` (n,): seconds from ``t0_ns``."""

    def __init__(self, path: Path, topic: str, reader):
        self.path, self.topic, self._reader = path, topic, reader
        self._connections = [c for c in reader.connections if c.topic == topic]
        log, stamps = [], []
        for _, log_ns, raw in messages(reader, self.path, connections=self._connections):
            log.append(log_ns)
            stamps.append(_header_stamp_ns(raw, log_ns))
        order = np.argsort(np.asarray(stamps, dtype=np.int64), kind="stable")
        self.log_ns = np.asarray(log, dtype=np.int64)[order]
        self.stamps_ns = np.asarray(stamps, dtype=np.int64)[order]
        self.t0_ns = int(self.stamps_ns[0]) if len(self.stamps_ns) else 0
        self.times_s = (self.stamps_ns - self.t0_ns) / 1e9

    def __len__(self) -> int:
        return len(self.stamps_ns)

    def index_at(self, t_s: float) -> int:
        """The last frame at or before ``t_s``; 0 before the first."""
        return max(0, int(np.searchsorted(self.times_s, t_s, side="right")) - 1)

    def image(self, k: int) -> np.ndarray:
        """Frame ``k`` as RGB (h, w, 3) uint8, read from the bag at its record time."""
        from calib_core.bags.bag_source import _rgb, deserialize

        if not 0 <= k < len(self):
            raise IndexError(f"frame {k} of a bag topic with {len(self)} images")
        log_ns = int(self.log_ns[k])
        for connection, _, raw in messages(
            self._reader, self.path, connections=self._connections, start=log_ns, stop=log_ns + 1
        ):
            if _header_stamp_ns(raw, log_ns) == self.stamps_ns[k]:
                message = deserialize(self._reader, raw, connection, f"{self.path} {self.topic} image {k}")
                return _rgb(message, connection.msgtype, f"{self.path} {self.topic} image {k}")
        raise FileFormatError(self.path, f"{self.topic}: image {k} (recorded at {log_ns} ns) could not be read again")


class BagPlayback:
    """A bag as a replay: ``frames`` (:class:`BagFrames`), ``joint_times_s`` (m,) and ``joints_deg`` (m, n) model joints
    (deg, mm; empty for a bag without the arm's joint states), ``setup`` (``{"intrinsics": ...}`` from its CameraInfo),
    ``duration_s``, no ``solves``. Close it (or use it as a context manager) to close the bag.

    Its public members are the recording playback protocol the replay reads (the frames, the joints and their times, the
    set-up, the solves, the pairs at a time) and what the bag was read from."""

    def __init__(
        self, path: str | Path, joint_names, per_si, *, topic: str | None = None, joint_topic: str | None = None
    ):
        self.path = Path(path)
        self.solves: list = []
        chosen = choose_image_topic(self.path, topic)  # an error lists the image topics, or says what the bag holds
        self._reader = reader = open_reader(self.path)
        try:
            self.frames = BagFrames(self.path, chosen.name, reader)
            n = len(list(joint_names))
            self.joint_topic = None
            self.joint_times_s, self.joints_deg = np.zeros(0), np.zeros((0, n))
            if any(c.msgtype == JOINT_STATE for c in reader.connections):
                track = read_joint_track(self.path, joint_names, per_si, joint_topic)
                self.joint_topic = track.topic
                self.joint_times_s = (track.stamps_ns - self.frames.t0_ns) / 1e9
                self.joints_deg = track.joints
            self.setup: dict = {}
            if len(self.frames):
                first = self.frames.image(0)
                intrinsics = bag_intrinsics(self.path, (first.shape[1], first.shape[0]))
                if intrinsics is not None:
                    self.setup["intrinsics"] = intrinsics.to_dict()
        except BaseException:
            self.close()
            raise
        self.duration_s = float(self.frames.times_s[-1]) if len(self.frames) else 0.0

    def close(self) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def frame_index_at(self, t_s: float) -> int | None:
        return self.frames.index_at(t_s) if len(self.frames) else None

    def joints_at(self, t_s: float) -> np.ndarray | None:
        """The last joint sample (deg) at or before ``t_s``; ``None`` before the first (or without joint states)."""
        i = int(np.searchsorted(self.joint_times_s, t_s, side="right")) - 1
        return None if i < 0 else self.joints_deg[i].copy()

    def pairs_at(self, t_s: float) -> list:
        return []

    def solve_at(self, t_s: float):
        return None


def is_ros2_mcap(path: str | Path) -> bool:
    """Whether an ``.mcap`` file is a ROS 2 bag (its profile says ``ros2``) rather than a videocal recording."""
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            return make_reader(f).get_header().profile == "ros2"
    except Exception:  # not an MCAP file at all: the recording reader says what it is
        return False


def is_bag(path: str | Path) -> bool:
    """Whether ``path`` is a ROS bag to replay (a bag folder, one of its storage files, a ``.db3``, an MCAP of
    profile ``ros2``) rather than a videocal recording."""
    from calib_core.bags.bag_source import looks_like_bag

    path = Path(path)
    if not looks_like_bag(path):
        return False
    return (
        path.is_dir()
        or (path.parent / "metadata.yaml").is_file()
        or path.suffix.lower() != ".mcap"
        or is_ros2_mcap(path)
    )
