"""A ROS bag as a source: its image topics (``sensor_msgs/msg/Image``, ``CompressedImage``) and ``CameraInfo``.

A bag is a bag folder (``metadata.yaml`` and its storage files), one of its ``.mcap``/``.db3`` files, or a lone
``.mcap`` file. Which image topic: the only one, or ``topic``; several without ``topic`` is an error listing them,
and a bag with none is an error naming what it holds (never an empty result).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from calib_core.errors import FileFormatError

IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
BAG_SUFFIXES = (".mcap", ".db3", ".bag")


def looks_like_bag(path: Path) -> bool:
    """A bag folder, a bag storage file, or an MCAP file (a videocal recording is told apart when it is read)."""
    path = Path(path)
    return (path.is_dir() and (path / "metadata.yaml").is_file()) or (
        path.is_file() and path.suffix.lower() in BAG_SUFFIXES
    )


@dataclass(frozen=True)
class Topic:
    name: str
    msgtype: str
    count: int

    def __str__(self) -> str:
        return f"{self.name} ({self.msgtype}, {self.count})"


def _bag_paths(path: Path) -> list[Path]:
    # A storage file inside a bag folder is read as the folder (its metadata says how).
    if path.is_file() and (path.parent / "metadata.yaml").is_file():
        return [path.parent]
    return [path]


def open_reader(path: str | Path):
    """The ``rosbags`` reader of ``path``, open (the caller closes it); :class:`FileFormatError` naming the file when
    it is not a readable bag."""
    from rosbags.highlevel import AnyReader

    path = Path(path)
    if not path.exists():
        raise FileFormatError(path, "no such bag (a bag folder, a .mcap or a .db3 file)")
    try:
        reader = AnyReader(_bag_paths(path))
        reader.open()
    except Exception as exc:  # rosbags raises its own errors per storage and profile
        raise FileFormatError(
            path,
            "not a ROS bag rosbags can read: "
            f"{str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__}",
        ) from None
    return reader


def messages(reader, path, **selection):
    """``reader.messages(**selection)``, each (connection, log time ns, raw bytes); :class:`FileFormatError` naming the
    bag when its storage turns out damaged on the way (a chunk whose checksum fails, a record cut short)."""
    iterator = reader.messages(**selection)
    while True:
        try:
            item = next(iterator)
        except StopIteration:
            return
        except Exception as exc:  # rosbags' reader errors, and struct/zstd errors on damaged chunks
            text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise FileFormatError(Path(path), f"the bag is damaged: {text}") from None
        yield item


def deserialize(reader, raw: bytes, connection, where: str):
    """``raw`` read as the connection's message type; :class:`FileFormatError` naming ``where`` (the bag, topic and
    message) when its bytes are not that message in CDR (a bag written by another serializer, or damaged)."""
    try:
        return reader.deserialize(raw, connection.msgtype)
    except Exception as exc:  # rosbags' own serde errors (and struct/index errors on truncated bytes)
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise FileFormatError(
            Path(where.split(" ")[0]), f"{where}: not a {connection.msgtype} in CDR ({text})"
        ) from None


@contextmanager
def open_bag(path: str | Path):
    """:func:`open_reader` for a ``with`` block."""
    reader = open_reader(path)
    try:
        yield reader
    finally:
        reader.close()


def bag_topics(path: str | Path) -> list[Topic]:
    with open_bag(path) as reader:
        counts: dict[tuple[str, str], int] = {}
        for c in reader.connections:
            counts[(c.topic, c.msgtype)] = counts.get((c.topic, c.msgtype), 0) + c.msgcount
    return [Topic(t, m, n) for (t, m), n in sorted(counts.items())]


def choose_image_topic(path: str | Path, topic: str | None = None) -> Topic:
    """The image topic to read (see the module)."""
    topics = bag_topics(path)
    images = [t for t in topics if t.msgtype in IMAGE_TYPES and t.count > 0]
    if topic is not None:
        for t in topics:
            if t.name == topic:
                if t.msgtype not in IMAGE_TYPES:
                    raise FileFormatError(
                        Path(path),
                        f"topic {topic} holds {t.msgtype}, not images; image topics: "
                        f"{', '.join(map(str, images)) or 'none'}",
                    )
                return t
        raise FileFormatError(Path(path), f"no topic {topic}; image topics: {', '.join(map(str, images)) or 'none'}")
    if len(images) == 1:
        return images[0]
    if not images:
        held = ", ".join(map(str, topics)) or "no messages at all"
        raise FileFormatError(Path(path), f"no images in this bag (it holds {held})")
    raise FileFormatError(Path(path), f"several image topics: choose one with --topic: {', '.join(map(str, images))}")


def _rgb(message, msgtype: str, where: str) -> np.ndarray:
    from calib_core.ros2.image_decoding import compressed_to_rgb, image_to_rgb

    return compressed_to_rgb(message, where) if msgtype.endswith("CompressedImage") else image_to_rgb(message, where)


def bag_images(path: str | Path, topic: str | None = None, every: int = 1) -> Iterator[tuple[str, np.ndarray]]:
    """(name, RGB image) of every ``every``-th image of the topic, in time order; the name is ``t_<stamp ns>``."""
    for _, name, image in bag_stamped_images(path, topic, every):
        yield name, image


def bag_stamped_images(
    path: str | Path, topic: str | None = None, every: int = 1
) -> Iterator[tuple[int, str, np.ndarray]]:
    """(header stamp ns, name, RGB image) of every ``every``-th image of the topic, in the bag's order; the stamp is
    the camera driver's (the bag's record time when the header has none)."""
    chosen = choose_image_topic(path, topic)
    with open_bag(path) as reader:
        connections = [c for c in reader.connections if c.topic == chosen.name]
        for k, (connection, log_ns, raw) in enumerate(messages(reader, path, connections=connections)):
            if k % every:
                continue
            message = deserialize(reader, raw, connection, f"{path} {chosen.name} message {k}")
            stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec or log_ns
            yield stamp, f"t_{stamp}", _rgb(message, connection.msgtype, f"{path} {chosen.name} message {k}")


def bag_intrinsics(path: str | Path, image_size: tuple[int, int]):
    """The intrinsics of the bag's first ``CameraInfo`` (ROS's ``k``, ``d``, ``distortion_model``), or ``None``;
    :class:`FileFormatError` names the bag and the topic for one videocal cannot use."""
    from calib_core.camera.intrinsics_io import _load_camera_info_message

    found = bag_camera_info(path)
    if found is None:
        return None
    topic, message = found
    data = {
        "width": int(message.width),
        "height": int(message.height),
        "distortion_model": str(message.distortion_model),
        "k": [float(v) for v in message.k],
        "d": [float(v) for v in message.d],
    }
    return _load_camera_info_message(Path(f"{path} {topic}"), data, image_size)


def bag_camera_info(path: str | Path):
    """The first ``CameraInfo`` of the bag as ``(topic, message)``, or None."""
    with open_bag(path) as reader:
        connections = [c for c in reader.connections if c.msgtype == CAMERA_INFO]
        for connection, _, raw in messages(reader, path, connections=connections):
            return connection.topic, deserialize(reader, raw, connection, f"{path} {connection.topic}")
    return None
