"""Reading a recording, tolerating a file cut off by a crash, and recovering such a file."""

from __future__ import annotations

import base64
import io
import json
import mmap
import os
import struct
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Attachment, Channel, Chunk, Footer, Message
from mcap.stream_reader import breakup_chunk
from mcap.writer import MCAP0_MAGIC as MAGIC

from calib_core.atomic_file import atomic_path
from calib_core.errors import FileFormatError
from calib_core.recording.recorder import SessionRecorder
from calib_core.recording.schemas import KNOWN_TOPICS, VIDEO_TOPIC


@dataclass(frozen=True)
class RecordedMessage:
    """One message: ``topic``, ``log_time_ns`` (Unix ns), ``payload`` (decoded JSON, or for a
    video frame ``{"timestamp", "frame_id", "format", "data": bytes}``) and ``raw`` (its bytes
    in the file)."""

    topic: str
    log_time_ns: int
    payload: dict
    raw: bytes = b""
    encoding: str = "json"


def _video_payload(data: bytes) -> dict:
    from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo

    m = CompressedVideo.FromString(data)
    return {
        "timestamp": {"sec": m.timestamp.seconds, "nsec": m.timestamp.nanos},
        "frame_id": m.frame_id,
        "format": m.format,
        "data": m.data,
    }


@dataclass
class RecordingContents:
    """What a pass over a file found: the messages, whether it ended cleanly, and why not;
    its attachments ``(name, media_type, data)``."""

    messages: list[RecordedMessage]
    complete: bool
    problem: str | None = None
    attachments: list[tuple[str, str, bytes]] = field(default_factory=list)

    def topic(self, name: str) -> list[RecordedMessage]:
        return [m for m in self.messages if m.topic == name]


_RECORD_HEADER = struct.Struct("<BQ")
_READERS = {
    Opcode.CHANNEL: Channel,
    Opcode.MESSAGE: Message,
    Opcode.CHUNK: Chunk,
    Opcode.ATTACHMENT: Attachment,
    Opcode.FOOTER: Footer,
}


def _records(data: bytes | mmap.mmap, problems: list[str]):
    """The file's top-level records in order, with the records inside each chunk. A damaged
    record (a chunk whose CRC fails, a record that does not parse) is skipped and described in
    ``problems``; reading goes on with the next one. Stops at the footer or where the file ends."""
    pos = len(MAGIC)
    chunk = 0
    while pos + _RECORD_HEADER.size <= len(data):
        opcode, length = _RECORD_HEADER.unpack_from(data, pos)
        body_start, end = pos + _RECORD_HEADER.size, pos + _RECORD_HEADER.size + length
        if end > len(data):
            problems.append(f"the file ends abruptly inside a record at byte {pos} (a crash or a cut)")
            return
        reader = _READERS.get(opcode)
        if reader is not None:
            try:
                stream = ReadDataStream(io.BytesIO(data[body_start:end]))
                record = reader.read(stream, length) if reader is Message else reader.read(stream)
                if isinstance(record, Chunk):
                    chunk += 1
                    yield from breakup_chunk(record, validate_crc=True)
                else:
                    yield record
            except Exception as exc:  # the mcap records raise assorted errors on damaged bytes
                what = f"chunk {chunk} at byte {pos}" if opcode == Opcode.CHUNK else f"record at byte {pos}"
                problems.append(f"{what} is damaged ({type(exc).__name__}): skipped")
            if opcode == Opcode.FOOTER:
                return
        pos = end
    if pos < len(data):
        problems.append(f"the file ends abruptly inside a record at byte {pos} (a crash or a cut)")


def read_recording(path: str | Path) -> RecordingContents:
    """Every readable message of a recording, in file order. A file cut short gives
    ``complete=False`` with the messages before the cut; a damaged chunk or message is skipped
    (``problem`` says which) and reading goes on. A file that is not an MCAP recording raises
    ``FileFormatError``."""
    path = Path(path)
    if path.is_dir():
        what = "a ROS bag folder" if (path / "metadata.yaml").is_file() else "a folder"
        raise FileFormatError(
            path,
            f"{what}, not a videocal recording (an .mcap file); ROS bags are read by calibrate-intrinsics, "
            "calibrate-hand-eye, calibrate-robot and the window's replay (gui --recording)",
        )
    try:
        handle = open(path, "rb")
    except FileNotFoundError:
        raise FileFormatError(path, "no such recording") from None
    except OSError as exc:
        raise FileFormatError(path, f"cannot be read ({exc.strerror})") from None
    with handle:
        size = os.fstat(handle.fileno()).st_size
        if size < len(MAGIC) or handle.read(len(MAGIC)) != MAGIC:
            raise FileFormatError(path, "not an MCAP recording (no MCAP magic at its start)")
        data = mmap.mmap(handle.fileno(), 0, access=mmap.ACCESS_READ)
    channels: dict[int, Channel] = {}
    messages: list[RecordedMessage] = []
    attachments: list[Attachment] = []
    problems: list[str] = []
    complete = bad_messages = 0
    with data:
        for record in _records(data, problems):
            if isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    bad_messages += 1
                    continue
                try:
                    payload = (
                        _video_payload(record.data)
                        if channel.topic == VIDEO_TOPIC and channel.message_encoding == "protobuf"
                        else (json.loads(record.data) if channel.message_encoding == "json" else {})
                    )
                except Exception:  # json and protobuf raise different errors on bad bytes
                    bad_messages += 1
                    continue
                messages.append(
                    RecordedMessage(
                        channel.topic, record.log_time, payload, bytes(record.data), channel.message_encoding
                    )
                )
            elif isinstance(record, Attachment):
                attachments.append(record)
            elif isinstance(record, Footer):
                complete = True
    if not any(m.topic in KNOWN_TOPICS for m in messages):
        # Another program's MCAP (a ROS 2 bag) or an empty one: replaying it would show "0 frames" and succeed.
        topics = sorted({f"{c.topic} ({c.message_encoding})" for c in channels.values()})
        held = (
            f"its topics: {', '.join(topics[:8])}{' ...' if len(topics) > 8 else ''}"
            if topics
            else "it holds no messages"
        )
        hint = (
            "; a ROS 2 bag is read by calibrate-intrinsics, calibrate-hand-eye, calibrate-robot and the window's "
            "replay (gui --recording)"
            if any("cdr" in t or "ros" in t for t in topics)
            else ""
        )
        raise FileFormatError(path, f"not a videocal recording: no videocal message ({held}){hint}")
    if bad_messages:
        problems.append(f"{bad_messages} message{'s' if bad_messages > 1 else ''} could not be decoded: skipped")
    if not complete and not any("ends" in p for p in problems):
        problems.append(
            f"the file ends without its footer after {len(messages)} messages (the recorder did not finish)"
        )
    return RecordingContents(
        messages,
        bool(complete),
        "; ".join(problems) or None,
        [(a.name, a.media_type, bytes(a.data)) for a in attachments],
    )


def decode_frame(payload: dict) -> np.ndarray:
    """The RGB image (h, w, 3) of a ``foxglove.CompressedImage`` payload (JPEG or PNG); video
    frames need their predecessors: see :class:`~calib_core.recording.frame_track.FrameTrack`."""
    data = np.frombuffer(base64.b64decode(payload["data"]), dtype=np.uint8)
    bgr = cv2.imdecode(data, cv2.IMREAD_COLOR)
    if bgr is None:
        raise ValueError("frame data could not be decoded")
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def recover(path: str | Path, out: str | Path) -> RecordingContents:
    """Rewrite a cut-off or damaged recording as a complete, indexed one with every readable
    message, in log-time order (older recordings were not always in order), with its attachments."""
    contents = read_recording(path)
    kept = [m for m in contents.messages if m.topic in KNOWN_TOPICS]  # a channel of another program has no schema here

    def complete(tmp: Path) -> None:  # the copy reads back whole, or nothing replaces ``out``
        back = read_recording(tmp)
        if not back.complete or len(back.messages) != len(kept):
            raise ValueError(back.problem or f"{len(back.messages)} of {len(kept)} messages read back")

    # written beside ``out`` and put in place whole: an existing file there is never left half overwritten
    with atomic_path(out, complete) as tmp:
        writer = SessionRecorder(tmp, hold_s=1e9)  # held until close, then written sorted by log time
        for name, media_type, data in contents.attachments:
            writer.record_attachment(name, media_type, data)
        for m in kept:
            writer.write_raw(m.topic, m.raw, log_time_ns=m.log_time_ns)
        writer.close(timeout_s=None)
        if writer.failure:
            raise OSError(f"writing {out}: {writer.failure}")
    return contents
