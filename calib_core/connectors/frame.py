"""What every camera connector delivers: the frame, and the source protocol every video source follows."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
from calib_core.errors import VideocalError


@dataclass(frozen=True)
class Frame:
    """One camera image.

    ``image``: (height, width, 3) uint8, **RGB** (converted from OpenCV's BGR at the source).
    ``index``: frame number in its source, from 0. ``t_host_s``: host clock
    (``time.monotonic()``) when the frame was captured, as near as the source knows (an OpenCV
    device: when ``read`` returned it, its latency later; the simulated camera: the exposure). The
    joint history stamps picks with the joints at this time, so the cell's settle time must cover
    the camera's latency. ``t_source_s``: the source's own timestamp (position in a file, capture
    time of a recording), or None. ``t_device_ns``: the camera's own timestamp of the exposure, ns (a ROS 2
    header stamp, a GenICam device tick), where the device stamps its frames; else None.
    """

    image: np.ndarray
    index: int
    t_host_s: float
    t_source_s: float | None = None
    t_device_ns: int | None = None

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in px."""
        return (int(self.image.shape[1]), int(self.image.shape[0]))


class FrameSource(ABC):
    """A source of frames. ``read()`` blocks for at most about one frame period.

    Sources are used from one thread at a time (the camera pane reads them on a worker
    thread). ``read()`` returns None at the end of a finite stream; a device that fails
    raises ``VideoSourceError``.
    """

    #: a human-readable description, e.g. "file clip.mp4" or "simulated camera"
    description: str = "video source"

    @property
    @abstractmethod
    def fps(self) -> float:
        """Nominal frame rate, frames per second (0 when unknown)."""

    @abstractmethod
    def read(self) -> Frame | None:
        """The next frame, or None at the end of the stream."""

    def close(self) -> None:
        """Release the device or file. Safe to call twice."""

    def __enter__(self) -> FrameSource:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class VideoSourceError(VideocalError, RuntimeError):
    """A video source could not be opened or stopped delivering frames; the message names it."""


class FrameTimeout(VideoSourceError):
    """A live source had no new frame within its wait: the camera or its stream may come back (the reader
    keeps reading and says it is waiting), unlike a :class:`VideoSourceError`, which ends it."""
