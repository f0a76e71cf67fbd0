"""Reading a camera off the GUI thread: a QThread that owns its frame source."""

from __future__ import annotations

import time
from collections.abc import Callable

from PySide6.QtCore import QThread, Signal

from calib_core.connectors.frame import FrameSource, FrameTimeout, VideoSourceError


class FrameWorker(QThread):
    """Creates the source in its own thread (a VTK-rendering source must live there), reads it
    at its frame rate and emits ``frame(Frame)``; ``failed(str)`` when the source breaks;
    ``waiting(str)`` while a live camera sends nothing (it keeps reading)."""

    frame = Signal(object)
    failed = Signal(str)
    waiting = Signal(str)

    def __init__(self, make_source: Callable[[], FrameSource], parent=None):
        super().__init__(parent)
        self._make_source = make_source
        self._running = True
        self.paused = False
        self.fps_measured = 0.0

    def stop(self) -> None:
        self._running = False
        self.wait(3000)

    def run(self) -> None:
        try:
            source = self._make_source()
        except Exception as exc:  # any failure to open is reported, never raised into Qt
            self.failed.emit(f"cannot open the camera: {exc}")
            return
        period = 1.0 / source.fps if source.fps > 0 else 0.0
        last = time.monotonic()
        try:
            while self._running:
                if self.paused:
                    self.msleep(30)
                    continue
                t0 = time.monotonic()
                try:
                    frame = source.read()
                except FrameTimeout as exc:  # a live camera gone quiet: say so, keep waiting for it
                    self.waiting.emit(str(exc))
                    continue
                except VideoSourceError as exc:
                    self.failed.emit(str(exc))
                    return
                if frame is None:
                    self.failed.emit(f"{source.description}: end of stream")
                    return
                self.frame.emit(frame)
                now = time.monotonic()
                self.fps_measured = 0.8 * self.fps_measured + 0.2 / max(now - last, 1e-6)
                last = now
                rest = period - (now - t0)
                if rest > 0:
                    self.msleep(int(rest * 1000))
        finally:
            source.close()
