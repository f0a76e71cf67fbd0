"""The one-way delay of a stream of stamped samples, where the sender stamps on the epoch clock (ROS 2's header
stamps): each sample's arrival on this host's epoch clock minus its stamp. It needs the two clocks in step (NTP
or PTP, as ROS 2 itself assumes for its stamps); a sender whose clock runs ahead gives negative delays, which are
kept as measured and shown as 0.

A stream answers nothing, so there is no round trip to time as :mod:`calib_core.link.round_trip` does; the
round trip of a command is taken as twice this delay (the path is assumed symmetric).
"""

from __future__ import annotations

import threading
from collections import deque

import numpy as np

RECENT = 200


class ArrivalDelay:
    """The last :data:`RECENT` delays (s): :attr:`one_way_s` is their median, :attr:`spread_s` four times their
    mean deviation from it (how much later than usual a sample may come, as TCP's ``4 rttvar``)."""

    def __init__(self, recent: int = RECENT):
        self._delays: deque[float] = deque(maxlen=recent)
        self._lock = threading.Lock()

    def add(self, stamp_s: float, arrival_s: float) -> None:
        """A sample stamped ``stamp_s`` (s since the epoch, the sender's clock) arrived at ``arrival_s`` (ours)."""
        delay = arrival_s - stamp_s
        if np.isfinite(delay):
            with self._lock:
                self._delays.append(delay)

    @property
    def samples(self) -> int:
        return len(self._delays)

    def one_way_s(self) -> float | None:
        """The median delay (s, at least 0), ``None`` before the first sample."""
        with self._lock:
            return None if not self._delays else max(0.0, float(np.median(self._delays)))

    @property
    def spread_s(self) -> float:
        """Four mean deviations of the delays from their median (s; 0 before two samples)."""
        with self._lock:
            if len(self._delays) < 2:
                return 0.0
            d = np.asarray(self._delays)
            return 4.0 * float(np.mean(np.abs(d - np.median(d))))
