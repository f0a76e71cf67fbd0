"""Taking a DDS reader's samples with a bounded wait (cyclonedds's ``take`` does not wait; ``take_iter``
waits without end while samples keep coming)."""

from __future__ import annotations


class Taker:
    """``take(n, timeout_s)``: up to ``n`` samples, waiting at most ``timeout_s`` for the first."""

    def __init__(self, reader):
        from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState, WaitSet

        from cyclonedds.internal import InvalidSample

        self.reader = reader
        self._invalid = InvalidSample
        self._condition = ReadCondition(reader, ViewState.Any | InstanceState.Any | SampleState.NotRead)
        self._waitset = WaitSet(reader.participant)
        self._waitset.attach(self._condition)

    def take(self, n: int, timeout_s: float) -> list:
        """Data samples only: the notes DDS sends when a writer leaves (an ``InvalidSample``) are dropped."""
        from cyclonedds.util import duration

        samples = self.reader.take(N=n, condition=self._condition)
        if not samples:
            self._waitset.wait(duration(microseconds=int(timeout_s * 1e6)))
            samples = self.reader.take(N=n, condition=self._condition)
        return [s for s in samples if not isinstance(s, self._invalid)]

    def close(self) -> None:
        """Delete the wait set and the reader (with its condition), once no thread takes from them."""
        from calib_core.ros2.participant import delete

        delete(self._waitset, self.reader)
