"""Video from OpenCV's ``VideoCapture``: a device index, a file or a network URL."""

from __future__ import annotations

import time

import cv2

from calib_core.connectors.frame import Frame, FrameSource, VideoSourceError


class OpenCVSource(FrameSource):
    """Frames (RGB) from ``cv2.VideoCapture(spec)``; files report their position as ``t_source_s``."""

    def __init__(self, spec: int | str):
        self.description = f"camera {spec}" if isinstance(spec, int) else f"video {spec}"
        self._cap = cv2.VideoCapture(spec)
        if not self._cap.isOpened():
            raise VideoSourceError(f"cannot open {self.description} with OpenCV")
        self._index = 0
        self._is_file = isinstance(spec, str) and "://" not in spec

    @property
    def fps(self) -> float:
        return float(self._cap.get(cv2.CAP_PROP_FPS) or 0.0)

    def read(self) -> Frame | None:
        ok, bgr = self._cap.read()
        if not ok:
            if self._is_file:
                return None
            raise VideoSourceError(f"{self.description} stopped delivering frames")
        t_source = self._cap.get(cv2.CAP_PROP_POS_MSEC) / 1000.0 if self._is_file else None
        frame = Frame(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), self._index, time.monotonic(), t_source)
        self._index += 1
        return frame

    def close(self) -> None:
        if self._cap is not None:
            self._cap.release()
            self._cap = None
