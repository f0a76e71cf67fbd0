"""Writing a recording. Crash safe: messages are written unchunked and flushed as they come,
so a file cut off by a crash holds every message before the cut (``recover`` rewrites it)."""

from __future__ import annotations

import base64
import json
import os
import threading
import time
from pathlib import Path

import cv2
import numpy as np
from mcap.writer import CompressionType, Writer

from calib_core import __version__
from calib_core.recording.schemas import CORRECTION_TOPIC, EVENT_TOPIC, FRAME_TOPIC, JOINTS_TOPIC, SETUP_TOPIC, SOLVE_TOPIC, TOPICS, schema_bytes

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
    """Record to ``path`` (``.mcap``). Thread-safe: frames, joints and edits come from different threads."""

    def __init__(self, path: str | Path, *, jpeg_quality: int = 90):
        self.path = Path(path)
        self._file = open(self.path, "wb")
        self._writer = Writer(self._file, compression=CompressionType.NONE, use_chunking=False, use_statistics=True, use_summary_offsets=True)
        self._writer.start(profile=PROFILE, library=f"videocal {__version__}")
        self._channels = {}
        for topic in TOPICS:
            schema_id = self._writer.register_schema(TOPICS[topic]["title"], "jsonschema", schema_bytes(topic))
            self._channels[topic] = self._writer.register_channel(topic, "json", schema_id)
        self._lock = threading.Lock()
        self._seq = 0
        self.jpeg_quality = jpeg_quality
        self.messages = 0
        self._solve_id = 0
        self._closed = False

    @property
    def size_bytes(self) -> int:
        return self._file.tell() if not self._closed else self.path.stat().st_size

    def _write(self, topic: str, payload: dict, log_time_ns: int | None = None) -> None:
        data = json.dumps(to_jsonable(payload), separators=(",", ":")).encode()
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
        ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(image_rgb, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
        if not ok:
            raise ValueError("frame could not be JPEG-encoded")
        now = time.time()
        self._write(FRAME_TOPIC, {"timestamp": {"sec": int(now), "nsec": int((now % 1) * 1e9)}, "frame_id": frame_id, "format": "jpeg", "data": base64.b64encode(jpeg.tobytes()).decode(), "t_host_s": t_host_s})

    def record_joints(self, seq: int, t_ms: int, t_host_s: float, joints_deg) -> None:
        self._write(JOINTS_TOPIC, {"seq": seq, "t_ms": t_ms, "t_host_s": t_host_s, "joints_deg": list(joints_deg)})

    def record_event(self, kind: str, **detail) -> None:
        self._write(EVENT_TOPIC, {"kind": kind, "detail": detail})

    def record_solve(self, inputs: dict, result: dict) -> int:
        self._solve_id += 1
        self._write(SOLVE_TOPIC, {"id": self._solve_id, "inputs": inputs, "result": result})
        return self._solve_id

    def record_correction(self, correction: dict) -> None:
        self._write(CORRECTION_TOPIC, correction)

    def close(self) -> None:
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
