"""The link's measured round trip, and the timeouts that follow it.

A remote cell may be far away (the original's operator worked over a relay satellite: seconds of delay), so
no timeout of the link may be a constant that only a near controller meets. The round trip is estimated
as TCP does (RFC 6298): a smoothed round trip ``srtt_s``, its mean deviation ``rttvar_s``, and a
retransmission-style timeout ``rto_s = srtt + 4 rttvar`` that a reply is late after. Samples come from
requests whose reply is unambiguous (Karn's rule: an answer to a request sent twice is not timed).
"""

from __future__ import annotations

import threading
from collections import deque

import numpy as np

_ALPHA, _BETA = 1.0 / 8.0, 1.0 / 4.0
"""RFC 6298's gains for the smoothed round trip and its deviation."""
RECENT = 15
"""Round trips kept for the delay shown."""


class RoundTrip:
    """The estimate from the round trips seen (s). Thread-safe; ``samples`` counts them. ``min_rto_s``
    bounds the timeout below (a near controller on a loaded machine still needs some)."""

    def __init__(self, min_rto_s: float = 1.0, max_rto_s: float = 60.0):
        self.min_rto_s = float(min_rto_s)
        self.max_rto_s = float(max_rto_s)
        self.srtt_s: float | None = None
        self.rttvar_s = 0.0
        self.last_s: float | None = None
        self.samples = 0
        self._recent: deque[float] = deque(maxlen=RECENT)
        self._backoff = 1
        self._lock = threading.Lock()

    def add(self, rtt_s: float) -> None:
        """One measured round trip (s); a negative one (clock trouble) is ignored."""
        if not (rtt_s >= 0.0):
            return
        with self._lock:
            if self.srtt_s is None:
                self.srtt_s, self.rttvar_s = rtt_s, rtt_s / 2.0
            else:
                self.rttvar_s = (1.0 - _BETA) * self.rttvar_s + _BETA * abs(self.srtt_s - rtt_s)
                self.srtt_s = (1.0 - _ALPHA) * self.srtt_s + _ALPHA * rtt_s
            self.last_s = rtt_s
            self.samples += 1
            self._recent.append(rtt_s)
            self._backoff = 1

    def timed_out(self) -> None:
        """A reply did not come within :attr:`rto_s`: wait twice as long next time, until one is timed
        (RFC 6298 5.5; without it a link further away than the first guess would never be timed)."""
        with self._lock:
            self._backoff = min(self._backoff * 2, 64)

    @property
    def measured(self) -> bool:
        return self.srtt_s is not None

    @property
    def rto_s(self) -> float:
        """How long to wait for a reply before it counts as late (s): ``srtt + 4 rttvar`` (``min_rto_s`` before
        the first sample), doubled for each :meth:`timed_out` since the last sample, within the bounds."""
        base = self.min_rto_s if self.srtt_s is None else max(self.min_rto_s, self.srtt_s + 4.0 * self.rttvar_s)
        return min(self.max_rto_s, base * self._backoff)

    @property
    def spread_s(self) -> float:
        """How much later than usual a message may arrive (s): ``4 rttvar`` (0 before the first sample)."""
        return 4.0 * self.rttvar_s

    def one_way_s(self) -> float | None:
        """Half the median of the last :data:`RECENT` round trips (s), ``None`` before the first: the delay the window
        shows. The median, not the smoothed mean the timeouts use: a lost segment's answer, a round trip late, would
        raise the mean above the link's usual delay."""
        with self._lock:
            return None if not self._recent else float(np.median(self._recent)) / 2.0
