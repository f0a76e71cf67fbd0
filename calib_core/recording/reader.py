"""Reading a recording, tolerating a file cut off by a crash, and recovering such a file."""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from mcap.exceptions import McapError
from mcap.records import Channel, Footer, Message
from mcap.stream_reader import StreamReader

from calib_core.atomic_file import atomic_path
from calib_core.errors import FileFormatError
from calib_core.recording.recorder import SessionRecorder
from calib_core.recording.schemas import CORRECTION_TOPIC, EVENT_TOPIC, FRAME_TOPIC, JOINTS_TOPIC, SETUP_TOPIC, SOLVE_TOPIC, VIDEO_TOPIC


@dataclass(frozen=True)
class RecordedMessage:
    """One message: ``topic``, ``log_time_ns`` (Unix ns), ``payload`` (decoded JSON, or for a
    video frame ``{"timestamp", "frame_id", "format", "data": bytes}``) and ``raw`` (its bytes
    in the file)."""

    topic: str
    log_time_ns: int
    payload: dict
    raw: bytes = b""


def _video_payload(data: bytes) -> dict:
    from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo

    m = CompressedVideo.FromString(data)
    return {"timestamp": {"sec": m.timestamp.seconds, "nsec": m.timestamp.nanos}, "frame_id": m.frame_id, "format": m.format, "data": m.data}


@dataclass
class RecordingContents:
    """What a pass over a file found: the messages, whether it ended cleanly, and why not."""

    messages: list[RecordedMessage]
    complete: bool
    problem: str | None = None

    def topic(self, name: str) -> list[RecordedMessage]:
        return [m for m in self.messages if m.topic == name]


def read_recording(path: str | Path) -> RecordingContents:
    """Every readable message of a recording; a file cut short gives ``complete=False`` with the
    messages before the cut. A file that is not a videocal MCAP recording raises ``FileFormatError``."""
    path = Path(path)
    try:
        handle = open(path, "rb")
    except FileNotFoundError:
        raise FileFormatError(path, "no such recording") from None
    channels: dict[int, str] = {}
    encodings: dict[int, str] = {}
    messages: list[RecordedMessage] = []
    complete, problem = False, None
    with handle:
        try:
            for record in StreamReader(handle, skip_magic=False).records:
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                    encodings[record.id] = record.message_encoding
                elif isinstance(record, Message):
                    topic = channels.get(record.channel_id)
                    if topic is None:
                        continue
                    encoding = encodings.get(record.channel_id)
                    try:
                        payload = _video_payload(record.data) if topic == VIDEO_TOPIC and encoding == "protobuf" else json.loads(record.data)
                    except Exception:  # json and protobuf raise different errors on bad bytes
                        problem = f"message {len(messages) + 1} on {topic} is not valid {encoding}"
                        break
                    messages.append(RecordedMessage(topic, record.log_time, payload, bytes(record.data)))
                elif isinstance(record, Footer):
                    complete = True
        except (McapError, ValueError, EOFError, OSError) as exc:
            if not messages and not channels:
                raise FileFormatError(path, f"not an MCAP recording ({exc})") from None
            problem = f"the file ends abruptly after {len(messages)} messages ({type(exc).__name__})"
        except Exception as exc:  # the mcap stream reader raises assorted errors on a truncated record
            if not messages and not channels:
                raise FileFormatError(path, f"not an MCAP recording ({exc})") from None
            problem = f"the file ends abruptly after {len(messages)} messages ({type(exc).__name__})"
    if not complete and problem is None:
        problem = f"the file ends without its footer after {len(messages)} messages (the recorder did not finish)"
    return RecordingContents(messages, complete, problem)


def decode_frame(payload: dict) -> np.ndarray:
    """The RGB image (h, w, 3) of a ``foxglove.CompressedImage`` payload (JPEG or PNG); video
    frames need their predecessors: see :class:`~calib_core.recording.frame_track.FrameTrack`."""
    data = np.frombuffer(base64.b64decode(payload["data"]), dtype=np.uint8)
    bgr = cv2.imdecode(data, cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError("frame data could not be decoded")
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def recover(path: str | Path, out: str | Path) -> RecordingContents:
    """Rewrite a cut-off recording as a complete one with every message before the cut."""
    contents = read_recording(path)
    topics = {FRAME_TOPIC, VIDEO_TOPIC, JOINTS_TOPIC, EVENT_TOPIC, SOLVE_TOPIC, CORRECTION_TOPIC, SETUP_TOPIC}

    def complete(tmp: Path) -> None:  # the copy reads back whole, or nothing replaces ``out``
        back = read_recording(tmp)
        if not back.complete:
            raise ValueError(back.problem)

    # written beside ``out`` and put in place whole: an existing file there is never left half overwritten
    with atomic_path(out, complete) as tmp:
        writer = SessionRecorder(tmp)
        for m in contents.messages:
            if m.topic in topics:
                writer.write_raw(m.topic, m.raw, log_time_ns=m.log_time_ns)
        writer.close()
    return contents
