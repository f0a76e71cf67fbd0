"""Writing a recording. Crash safe: messages are written unchunked and flushed as they come,
so a file cut off by a crash holds every message before the cut (``recover`` rewrites it).

Camera frames are H.264 by default (see ``video_codec``), encoded on the recorder's own thread so
the caller (the window's GUI thread) only queues them; ``frames="jpeg"`` records JPEG images."""

from __future__ import annotations

import base64
import json
import os
import queue
import threading
import time
from pathlib import Path

import cv2
import numpy as np
from mcap.writer import CompressionType, Writer

from calib_core import __version__
from calib_core.recording.schemas import CORRECTION_TOPIC, EVENT_TOPIC, FRAME_TOPIC, JOINTS_TOPIC, SETUP_TOPIC, SOLVE_TOPIC, TOPICS, VIDEO_TOPIC, schema_bytes, video_schema
from calib_core.recording.video_codec import DEFAULT_CRF, H264Encoder

FRAME_FORMATS = ("h264", "jpeg")

PROFILE = "videocal"


def to_jsonable(value):
    """numpy arrays and scalars as lists and numbers, recursively."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    return value


class SessionRecorder:
    """Record to ``path`` (``.mcap``). Thread-safe: frames, joints and edits come from different threads.

    ``frames``: "h264" (default; ``crf`` sets the quality, lower is better) or "jpeg"
    (``jpeg_quality``). ``frames_written`` and ``frames_dropped`` count what reached the file and
    what the encoder could not keep up with (a full queue of ``queue_frames``); a recorder made
    with ``drop_when_busy=False`` waits instead (for scripts that record faster than real time)."""

    def __init__(self, path: str | Path, *, frames: str = "h264", jpeg_quality: int = 90, crf: int = DEFAULT_CRF, fps: float = 15.0, queue_frames: int = 60, drop_when_busy: bool = True):
        if frames not in FRAME_FORMATS:
            raise ValueError(f"frames must be one of {', '.join(FRAME_FORMATS)}, got {frames!r}")
        self.path = Path(path)
        self.frames = frames
        self.crf, self.fps = crf, fps
        self.drop_when_busy = drop_when_busy
        self._file = open(self.path, "wb")
        self._writer = Writer(self._file, compression=CompressionType.NONE, use_chunking=False, use_statistics=True, use_summary_offsets=True)
        self._writer.start(profile=PROFILE, library=f"videocal {__version__}")
        self._channels = {}
        for topic in TOPICS:
            schema_id = self._writer.register_schema(TOPICS[topic]["title"], "jsonschema", schema_bytes(topic))
            self._channels[topic] = self._writer.register_channel(topic, "json", schema_id)
        name, data = video_schema()
        self._channels[VIDEO_TOPIC] = self._writer.register_channel(VIDEO_TOPIC, "protobuf", self._writer.register_schema(name, "protobuf", data))
        self._lock = threading.Lock()
        self.frames_written = 0
        self.frames_dropped = 0
        self._encoder: H264Encoder | None = None
        self._queue: queue.Queue = queue.Queue(maxsize=queue_frames)
        self._encoder_thread: threading.Thread | None = None
        self._seq = 0
        self.jpeg_quality = jpeg_quality
        self.messages = 0
        self._solve_id = 0
        self._closed = False

    @property
    def size_bytes(self) -> int:
        return self._file.tell() if not self._closed else self.path.stat().st_size

    def _write(self, topic: str, payload: dict, log_time_ns: int | None = None) -> None:
        self.write_raw(topic, json.dumps(to_jsonable(payload), separators=(",", ":")).encode(), log_time_ns)

    def write_raw(self, topic: str, data: bytes, log_time_ns: int | None = None) -> None:
        """Write an already encoded message (JSON, or protobuf on ``VIDEO_TOPIC``)."""
        t = time.time_ns() if log_time_ns is None else log_time_ns
        with self._lock:
            if self._closed:
                raise RuntimeError(f"recording {self.path} is closed")
            self._seq += 1
            self._writer.add_message(self._channels[topic], log_time=t, data=data, publish_time=t, sequence=self._seq)
            self._file.flush()
            self.messages += 1

    def record_setup(self, **setup) -> None:
        self._write(SETUP_TOPIC, {"videocal_version": __version__, **setup})

    def record_frame(self, image_rgb: np.ndarray, t_host_s: float, frame_id: str = "camera") -> None:
        """Record an RGB frame (h, w, 3) uint8 taken at ``t_host_s`` (host monotonic s). H.264
        frames are queued for the encoder thread and never block; a full queue drops the frame
        and counts it in ``frames_dropped`` (unless the recorder was made to wait)."""
        now_ns = time.time_ns()
        if self.frames == "jpeg":
            ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(image_rgb, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
            if not ok:
                raise ValueError("frame could not be JPEG-encoded")
            self._write(FRAME_TOPIC, {"timestamp": {"sec": now_ns // 10**9, "nsec": now_ns % 10**9}, "frame_id": frame_id, "format": "jpeg", "data": base64.b64encode(jpeg.tobytes()).decode(), "t_host_s": t_host_s}, now_ns)
            self.frames_written += 1
            return
        if self._closed:
            raise RuntimeError(f"recording {self.path} is closed")
        if self._encoder_thread is None:
            self._encoder_thread = threading.Thread(target=self._encode_loop, name="recording-encoder", daemon=True)
            self._encoder_thread.start()
        try:
            self._queue.put((image_rgb, now_ns, frame_id), block=not self.drop_when_busy)
        except queue.Full:
            self.frames_dropped += 1

    def _encode_loop(self) -> None:
        from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo

        while True:
            item = self._queue.get()
            if item is None:
                return
            image, now_ns, frame_id = item
            h, w = image.shape[:2]
            image = image[: h - h % 2, : w - w % 2]  # 4:2:0 needs even sizes: drop an odd last row/column
            if self._encoder is None or (self._encoder.height, self._encoder.width) != image.shape[:2]:
                self._encoder = H264Encoder(image.shape[1], image.shape[0], fps=self.fps, crf=self.crf)
            packet = self._encoder.encode(image)
            if not packet:
                continue
            message = CompressedVideo(frame_id=frame_id, data=packet, format="h264")
            message.timestamp.FromNanoseconds(now_ns)
            try:
                self.write_raw(VIDEO_TOPIC, message.SerializeToString(), now_ns)
                self.frames_written += 1
            except RuntimeError:
                return

    def record_joints(self, seq: int, t_ms: int, t_host_s: float, joints_deg) -> None:
        self._write(JOINTS_TOPIC, {"seq": seq, "t_ms": t_ms, "t_host_s": t_host_s, "joints_deg": list(joints_deg)})

    def record_event(self, kind: str, **detail) -> None:
        self._write(EVENT_TOPIC, {"kind": kind, "detail": detail})

    def record_solve(self, inputs: dict, result: dict, context: dict | None = None) -> int:
        """A solve: ``inputs`` to re-solve it, its ``result``, and the ``context`` that turns it
        into an end-effector estimate (obj2world, cam2world_model, tcp2base_model (4, 4) mm, joints)."""
        self._solve_id += 1
        self._write(SOLVE_TOPIC, {"id": self._solve_id, "inputs": inputs, "result": result, **({"context": context} if context else {})})
        return self._solve_id

    def record_correction(self, correction: dict) -> None:
        self._write(CORRECTION_TOPIC, correction)

    def close(self) -> None:
        """Encode the frames still queued, then finish the file (summary, footer) and fsync it."""
        if self._encoder_thread is not None:
            self._queue.put(None)
            self._encoder_thread.join()
            self._encoder_thread = None
        with self._lock:
            if self._closed:
                return
            self._writer.finish()
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
            self._closed = True

    def __enter__(self) -> SessionRecorder:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
