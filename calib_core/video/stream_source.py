"""A network camera stream (RTSP, HTTP MJPEG) through OpenCV's FFmpeg back end, opened again when it drops.

An IP camera restarts, a switch reboots, a Wi-Fi bridge goes away for a few seconds: the stream ends, FFmpeg says
so, and the camera usually comes back at the same URL. Until it does, :meth:`read` raises
:class:`~calib_core.connectors.frame.FrameTimeout` (the reader keeps reading and the window says it is waiting), and
tries to open the stream again every ``reopen_every_s``. FFmpeg's own waits are bounded (``timeout_s``) so a
stream that hangs instead of ending cannot freeze the reader.
"""

from __future__ import annotations

import time

import cv2

from calib_core.connectors.frame import Frame, FrameSource, FrameTimeout, VideoSourceError


class StreamSource(FrameSource):
    """Frames (RGB) of the stream at ``url``; the first open must succeed (a wrong URL is an error at once), later
    drops are waited out. ``reconnects`` counts the streams opened again."""

    def __init__(self, url: str, *, timeout_s: float = 5.0, reopen_every_s: float = 1.0):
        self.url = url
        self.description = f"stream {url}"
        self.timeout_s = float(timeout_s)
        self.reopen_every_s = float(reopen_every_s)
        self.reconnects = 0
        self._index = 0
        self._down_since: float | None = None
        self._last_try_s = 0.0
        self._cap = self._open()
        if self._cap is None:
            raise VideoSourceError(
                f"cannot open {self.description} with OpenCV's FFmpeg back end (wrong URL, or the camera is not "
                "serving?)"
            )

    def _open(self):
        ms = int(self.timeout_s * 1000)
        cap = cv2.VideoCapture(
            self.url, cv2.CAP_FFMPEG, [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, ms, cv2.CAP_PROP_READ_TIMEOUT_MSEC, ms]
        )
        if cap.isOpened():
            return cap
        cap.release()
        return None

    @property
    def fps(self) -> float:
        return float(self._cap.get(cv2.CAP_PROP_FPS) or 0.0) if self._cap is not None else 0.0

    def read(self) -> Frame | None:
        if self._cap is None:
            self._reopen()
        ok, bgr = self._cap.read()
        if not ok:
            self._cap.release()
            self._cap = None
            self._down_since = time.monotonic()
            raise FrameTimeout(f"{self.description} dropped: opening it again every {self.reopen_every_s:g} s")
        self._down_since = None
        frame = Frame(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), self._index, time.monotonic(), None)
        self._index += 1
        return frame

    def _reopen(self) -> None:
        """One try to open the stream again (after ``reopen_every_s`` since the last); FrameTimeout if it is still
        gone."""
        wait = self._last_try_s + self.reopen_every_s - time.monotonic()
        if wait > 0:
            time.sleep(wait)  # the reader's thread: nothing to read until the next try
        self._last_try_s = time.monotonic()
        self._cap = self._open()
        if self._cap is None:
            gone = time.monotonic() - (self._down_since or self._last_try_s)
            raise FrameTimeout(
                f"{self.description}: no frame for {gone:.0f} s (the stream is gone; opening it again every "
                f"{self.reopen_every_s:g} s)"
            )
        self.reconnects += 1

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
            self._cap = None
