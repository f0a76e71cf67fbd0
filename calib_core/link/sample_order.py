"""Which joint samples are fresh: the driver delivers each sample once, in order, and never an old one.

A sample whose sequence number repeats or goes back, or whose controller time goes back, is not the robot
now (``backwards``); a controller time more than 1 s back, or back to its first half second, is a restarted
controller, whose samples are fresh again (``restart``). Gaps in the sequence are counted.
"""

from __future__ import annotations

from calib_core.connectors.link_types import LinkStats
from calib_core.link.protocol import SEQ_MODULUS, JointSample

RESTART_BACK_MS = 1000  # a controller clock that goes back further than this has restarted ...
FRESH_CLOCK_MS = 500  # ... as has one that went back to its first half second


class SampleOrder:
    """The order of the samples delivered so far; :meth:`admit` decides on the next and counts in ``stats``."""

    def __init__(self, stats: LinkStats):
        self.stats = stats
        self._last_seq: int | None = None
        self._last_t_ms: int | None = None

    def admit(self, sample: JointSample) -> bool:
        """True when ``sample`` is to be delivered (fresh, or the first of a restarted controller)."""
        seq, t_ms = sample.seq, sample.t_ms
        if self._last_seq is not None and self._last_t_ms is not None:
            back = (self._last_seq - seq) % SEQ_MODULUS
            if 0 < back < SEQ_MODULUS // 2 or back == 0 or t_ms < self._last_t_ms:
                if self._last_t_ms - t_ms > RESTART_BACK_MS or t_ms < FRESH_CLOCK_MS:
                    self.stats.controller_restarts += 1  # its clock and count start again: fresh
                    self._last_seq = None
                else:
                    self.stats.backwards_samples += 1  # a repeat or an old sample: not the robot now
                    return False
        if self._last_seq is not None:
            expected = (self._last_seq + 1) % SEQ_MODULUS
            if seq != expected:
                self.stats.seq_gaps += 1
                skipped = (seq - expected) % SEQ_MODULUS
                if skipped < SEQ_MODULUS // 2:  # otherwise the controller restarted its count
                    self.stats.missing_samples += skipped
        self._last_seq, self._last_t_ms = seq, t_ms
        return True
