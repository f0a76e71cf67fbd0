"""Writing a recording: a chunked, indexed MCAP file that a crash cuts short by at most a second.

One writer thread owns the file. Callers (the GUI thread, the link's thread) only queue: camera
frames go to the encoder (H.264 by default, see ``video_codec``; or JPEG), every other message to
a time-ordered buffer. The writer thread writes messages in log-time order, holding each for
``hold_s`` and until no frame captured before it is still being encoded, so log times never go
backwards in the file even though a frame is written after the joint samples that arrived while
it was encoded. A chunk spans ``chunk_every_s`` of log time; it is closed (with its CRC and
message index) and handed to the operating system when the next message is past that, or when
the recorder's clock is (a quiet spell): a killed process loses at most that much plus the hold.
``close`` writes the summary (chunk index, statistics) that indexed readers open the file by.

A failing disk or encoder does not raise into the caller: the recorder stops, ``failure`` says
why, later messages are counted in ``messages_lost``, and ``close`` returns within its timeout.
"""

from __future__ import annotations

import heapq
import itertools
import json
import math
import os
import queue
import threading
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer

from calib_core import __version__
from calib_core.errors import FileWriteError
from calib_core.recording.frame_message import FrameEncoder
from calib_core.recording.schemas import (
    CORRECTION_TOPIC,
    EVENT_TOPIC,
    JOINTS_TOPIC,
    SETUP_TOPIC,
    SOLVE_TOPIC,
    TOPICS,
    schema_bytes,
)
from calib_core.recording.video_codec import DEFAULT_CRF

PROFILE = "videocal"
CLOSE_TIMEOUT_S = 1.0


def to_jsonable(value):
    """numpy arrays and scalars as lists and numbers, recursively; JSON has no NaN or infinity: a
    non-finite number is written as ``null``."""
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    return value


class RecorderClosedError(RuntimeError):
    """A message was given to a recorder after ``close``."""


_STOP = object()
_FLUSH = object()


class SessionRecorder:
    """Record to ``path`` (``.mcap``). Thread-safe: frames, joints and edits come from different threads.

    ``frames``: "h264" (default; ``crf`` sets the quality, lower is better) or "jpeg"
    (``jpeg_quality``). ``clock`` gives host seconds (default ``time.monotonic``, the clock of
    frames' and samples' ``t_host_s``); a script recording in simulated time passes its own.
    Counters: ``messages`` and ``frames_written`` are in chunks handed to the OS (what a crash
    keeps), ``frames_dropped`` frames the encoder could not keep up with (a full queue of
    ``queue_frames``; a recorder made with ``drop_when_busy=False`` waits instead),
    ``late_messages`` messages whose log time had to be raised to keep the file in order.

    Its public members: its settings (given once, read back by the status line and the tests), its counters (frames
    written and dropped, late and lost messages, size, failure), one ``record_*`` for each channel it writes, and flush,
    close and wait."""

    def __init__(
        self,
        path: str | Path,
        *,
        frames: str = "h264",
        jpeg_quality: int = 90,
        crf: int = DEFAULT_CRF,
        fps: float = 15.0,
        queue_frames: int = 60,
        drop_when_busy: bool = True,
        clock=time.monotonic,
        chunk_every_s: float = 0.5,
        hold_s: float = 0.3,
        camera_frame: str = "camera",
    ):
        self._frame_encoder = FrameEncoder(
            frames, fps=fps, crf=crf, jpeg_quality=jpeg_quality
        )  # checks ``frames`` first
        self.path = Path(path)
        self.frames, self.crf, self.fps, self.jpeg_quality = frames, crf, fps, jpeg_quality
        self.drop_when_busy = drop_when_busy
        self.camera_frame = camera_frame
        self.clock = clock
        self._unix_minus_host_ns = time.time_ns() - int(round(clock() * 1e9))
        self.chunk_every_ns, self.hold_ns = int(chunk_every_s * 1e9), int(hold_s * 1e9)
        try:
            self._file = open(self.path, "wb")
        except OSError as exc:  # a read-only or missing folder, a full disk: the operator's to mend, not a bug
            raise FileWriteError(self.path, f"cannot record here ({exc.strerror or exc})") from None
        self._writer = Writer(
            self._file,
            compression=CompressionType.LZ4,
            chunk_size=4 * 1024 * 1024,
            enable_crcs=True,
            enable_data_crcs=True,
        )
        self._writer.start(profile=PROFILE, library=f"videocal {__version__}")
        self._channels: dict[str, int] = {}
        self._schemas: dict[tuple[str, str], int] = {}
        self._sequence: dict[str, int] = defaultdict(int)
        self._lock = threading.Lock()
        self._pending: list = []  # heap of (log_ns, order, topic, data, is_frame)
        self._order = itertools.count()
        self._frames_in_encoder: dict[int, int] = {}  # order -> capture ns, of frames queued and not yet written
        self._queue: queue.Queue = queue.Queue(maxsize=queue_frames)
        self._last_written_ns = 0
        self._chunk_messages = self._chunk_frames = 0
        self._chunk_start_ns: int | None = None  # log time of the first message of the open chunk
        self._bytes = self._file.tell()
        self.messages = self.frames_written = self.frames_dropped = self.late_messages = self.messages_lost = 0
        self.failure: str | None = None
        self._solve_id = 0
        self._closing = False
        self._closed = False
        self._deadline: float | None = None
        self._thread = threading.Thread(target=self._run, name="recording-writer", daemon=True)
        self._thread.start()

    # --- time ------------------------------------------------------------------------------------
    def unix_ns(self, t_host_s: float | None = None) -> int:
        """The Unix time (ns) of host time ``t_host_s`` (s, the recorder's ``clock``); now by default."""
        return int(round((self.clock() if t_host_s is None else t_host_s) * 1e9)) + self._unix_minus_host_ns

    @property
    def size_bytes(self) -> int:
        """Bytes handed to the OS so far."""
        return self._bytes

    @property
    def failed(self) -> bool:
        return self.failure is not None

    # --- queuing (any thread) --------------------------------------------------------------------
    def _accepting(self) -> bool:
        if self._closing:
            raise RecorderClosedError(f"recording {self.path} is closed")
        if self.failure is not None:
            self.messages_lost += 1
            return False
        return True

    def write_raw(self, topic: str, data: bytes, log_time_ns: int | None = None) -> None:
        """Queue an already encoded message (JSON, or protobuf on a Foxglove topic) at ``log_time_ns``
        (Unix ns, default now)."""
        if not self._accepting():
            return
        t = self.unix_ns() if log_time_ns is None else int(log_time_ns)
        with self._lock:
            heapq.heappush(self._pending, (t, next(self._order), topic, bytes(data), False))

    def _write(self, topic: str, payload: dict, log_time_ns: int | None = None) -> None:
        self.write_raw(
            topic, json.dumps(to_jsonable(payload), separators=(",", ":"), allow_nan=False).encode(), log_time_ns
        )

    def record_message(self, topic: str, message, t_host_s: float | None = None) -> None:
        """A protobuf message (a Foxglove schema) on ``topic`` at host time ``t_host_s`` (default now)."""
        self.write_raw(topic, message.SerializeToString(), self.unix_ns(t_host_s))

    def record_attachment(self, name: str, media_type: str, data: bytes) -> None:
        """A file kept with the recording (MCAP attachment), e.g. the robot description."""
        if not self._accepting():
            return
        t = self.unix_ns()
        with self._lock:
            heapq.heappush(self._pending, (t, next(self._order), None, (name, media_type, bytes(data)), False))

    def record_setup(self, **setup) -> None:
        self._write(
            SETUP_TOPIC,
            {"videocal_version": __version__, "frames": self.frames, "camera_frame": self.camera_frame, **setup},
        )

    def record_frame(self, image_rgb: np.ndarray, t_host_s: float, frame_id: str | None = None) -> None:
        """Record an RGB frame (h, w, 3) uint8 captured at ``t_host_s`` (host s): its log time and
        ``timestamp`` are the capture time. Never blocks (unless made with ``drop_when_busy=False``):
        a full queue drops the frame and counts it in ``frames_dropped``."""
        if not self._accepting():
            return
        capture_ns = self.unix_ns(t_host_s)
        order = next(self._order)
        with self._lock:
            self._frames_in_encoder[order] = capture_ns
        item = (order, image_rgb, capture_ns, t_host_s, frame_id or self.camera_frame)
        while True:
            try:
                self._queue.put(item, block=not self.drop_when_busy, timeout=None if self.drop_when_busy else 0.1)
                return
            except queue.Full:
                if self.drop_when_busy or self.failure is not None:  # a waiting caller must not wait on a dead writer
                    break
        with self._lock:
            self._frames_in_encoder.pop(order, None)
        self.frames_dropped += 1

    def record_joints(self, seq: int, t_ms: int, t_host_s: float, joints_deg) -> None:
        """A joint sample received at ``t_host_s`` (host s), logged at that time."""
        self._write(
            JOINTS_TOPIC,
            {"seq": seq, "t_ms": t_ms, "t_host_s": t_host_s, "joints_deg": list(joints_deg)},
            self.unix_ns(t_host_s),
        )

    def record_event(self, kind: str, **detail) -> None:
        self._write(EVENT_TOPIC, {"kind": kind, "detail": detail})

    def record_solve(self, inputs: dict, result: dict, context: dict | None = None) -> int:
        """A solve: ``inputs`` to re-solve it, its ``result``, and the ``context`` that turns it
        into an end-effector estimate (obj2world, cam2world_model, tcp2base_model (4, 4) mm, joints)."""
        self._solve_id += 1
        self._write(
            SOLVE_TOPIC,
            {"id": self._solve_id, "inputs": inputs, "result": result, **({"context": context} if context else {})},
        )
        return self._solve_id

    def record_correction(self, correction: dict) -> None:
        self._write(CORRECTION_TOPIC, correction)

    # --- the writer thread -----------------------------------------------------------------------
    def _run(self) -> None:
        try:
            while True:
                try:
                    item = self._queue.get(timeout=0.05)
                except queue.Empty:
                    item = None
                if item is _STOP:
                    break
                if isinstance(item, tuple) and item[0] is _FLUSH:
                    self._release(None)
                    self._flush_chunk()
                    item[1].set()
                    continue
                if item is not None:
                    self._take(item)
                self._release(self.unix_ns() - self.hold_ns)
                if (
                    self._chunk_start_ns is not None
                    and self.unix_ns() - self._chunk_start_ns >= self.chunk_every_ns + self.hold_ns
                ):
                    self._flush_chunk()  # a quiet spell: what was written reaches the disk anyway
            self._drain()
            self._release(None)
            self._writer.finish()
            self._file.flush()
            os.fsync(self._file.fileno())
            self._bytes = self._file.tell()
            self.messages += self._chunk_messages
            self.frames_written += self._chunk_frames
            self._chunk_messages = self._chunk_frames = 0
        except Exception as exc:  # a full disk, a codec error: the caller learns it from ``failure``
            self.failure = f"{type(exc).__name__}: {exc}"
        finally:
            try:
                self._file.close()
            except OSError as exc:
                self.failure = self.failure or f"closing the file: {exc}"

    def _drain(self) -> None:
        """Encode the frames still queued at close, until its deadline; the rest are dropped and counted."""
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is _STOP:
                continue
            if isinstance(item, tuple) and item[0] is _FLUSH:
                item[1].set()
                continue
            self._take(item)

    def _take(self, item) -> None:
        """Encode a queued frame; once ``close``'s deadline has passed, drop it (counted)."""
        if self._deadline is not None and time.monotonic() > self._deadline:
            with self._lock:
                self._frames_in_encoder.pop(item[0], None)
            self.frames_dropped += 1
            return
        self._encode(item)

    def _encode(self, item) -> None:
        order, image, capture_ns, t_host_s, frame_id = item
        try:
            message = self._frame_encoder.encode(image, capture_ns, t_host_s, frame_id)
            if message is not None:
                with self._lock:
                    heapq.heappush(self._pending, (capture_ns, order, *message, True))
        finally:
            with self._lock:
                self._frames_in_encoder.pop(order, None)

    def _release(self, watermark_ns: int | None) -> None:
        """Write every queued message logged at or before ``watermark_ns`` (all with ``None``) and
        before any frame still being encoded, in log-time order."""
        while True:
            with self._lock:
                if not self._pending:
                    return
                limit = watermark_ns
                if limit is not None and self._frames_in_encoder:
                    limit = min(limit, min(self._frames_in_encoder.values()) - 1)
                if limit is not None and self._pending[0][0] > limit:
                    return
                log_ns, _, topic, data, is_frame = heapq.heappop(self._pending)
            if log_ns < self._last_written_ns:  # a frame that reached the recorder after newer messages were written
                log_ns = self._last_written_ns
                self.late_messages += 1
            self._last_written_ns = log_ns
            if topic is None:
                name, media_type, blob = data
                self._writer.add_attachment(
                    create_time=log_ns, log_time=log_ns, name=name, media_type=media_type, data=blob
                )
                continue
            if self._chunk_start_ns is None:
                self._chunk_start_ns = log_ns
            elif log_ns - self._chunk_start_ns >= self.chunk_every_ns:
                self._flush_chunk()  # a chunk spans chunk_every_s of log time: what a crash can lose, what a seek reads
                self._chunk_start_ns = log_ns
            self._sequence[topic] += 1
            self._writer.add_message(
                self._channel(topic), log_time=log_ns, data=data, publish_time=log_ns, sequence=self._sequence[topic]
            )
            self._chunk_messages += 1
            self._chunk_frames += is_frame

    def _flush_chunk(self) -> None:
        self._writer.flush()  # closes the chunk in progress, with its CRC and message index
        self._chunk_start_ns = None
        self._bytes = self._file.tell()
        self.messages += self._chunk_messages
        self.frames_written += self._chunk_frames
        self._chunk_messages = self._chunk_frames = 0

    def _channel(self, topic: str) -> int:
        """The channel of ``topic``, registered with its schema on first use: a recording lists only
        the topics it has messages on."""
        channel = self._channels.get(topic)
        if channel is None:
            if topic in TOPICS:
                name, encoding, data, message_encoding = (
                    TOPICS[topic]["title"],
                    "jsonschema",
                    schema_bytes(topic),
                    "json",
                )
            else:
                from calib_core.recording.foxglove_messages import protobuf_schema

                name, data = protobuf_schema(topic)
                encoding = message_encoding = "protobuf"
            key = (name, encoding)
            if key not in self._schemas:
                self._schemas[key] = self._writer.register_schema(name, encoding, data)
            channel = self._channels[topic] = self._writer.register_channel(topic, message_encoding, self._schemas[key])
        return channel

    def flush(self, timeout_s: float = 5.0) -> bool:
        """Write everything queued so far (frames encoded first) as a closed chunk, now; ``False``
        when the writer did not get to it within ``timeout_s`` (or has failed)."""
        if self._closing or self.failure is not None:
            return False
        done = threading.Event()
        try:
            self._queue.put((_FLUSH, done), timeout=timeout_s)
        except queue.Full:
            return False
        return done.wait(timeout_s) and self.failure is None

    # --- closing ---------------------------------------------------------------------------------
    def close(self, timeout_s: float | None = CLOSE_TIMEOUT_S) -> None:
        """Write what is queued, the summary and the footer, and fsync. Frames still waiting for the
        encoder after ``timeout_s`` are dropped (counted); a recorder made with ``drop_when_busy=False``
        waits for all of them. Returns within about ``timeout_s`` whatever happened: a writer still
        busy then (a slow frame, a slow disk) finishes the file on its own (``finished`` tells, and
        :meth:`wait_finished` waits); a failed one leaves the file as a crash would (``recover``)."""
        if self._closed:
            return
        self._closing = True
        wait = None if not self.drop_when_busy else timeout_s
        self._deadline = None if wait is None else time.monotonic() + wait
        end = None if wait is None else time.monotonic() + wait
        while self._thread.is_alive():
            try:
                self._queue.put(_STOP, timeout=0.05)
                break
            except queue.Full:
                if end is not None and time.monotonic() > end:
                    break
        self._thread.join(None if end is None else max(0.0, end - time.monotonic()))
        self._closed = True

    @property
    def finished(self) -> bool:
        """The file is complete: summary, footer and fsync done."""
        return self._closed and not self._thread.is_alive() and self.failure is None

    def wait_finished(self, timeout_s: float | None = None) -> bool:
        """After :meth:`close`: wait for the writer to finish the file; ``finished``."""
        self._thread.join(timeout_s)
        return self.finished

    def __enter__(self) -> SessionRecorder:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
