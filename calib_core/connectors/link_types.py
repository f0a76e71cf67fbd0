"""What every controller connector reports: its state, timestamped joint samples, statistics, move outcomes.

The types a connector speaks, whatever its wire (videocal's own protocol, ROS 2, RTDE, a user's plug-in)."""

from __future__ import annotations

from concurrent.futures import Future, InvalidStateError
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass
from enum import Enum

from calib_core.errors import VideocalError


@dataclass(frozen=True)
class JointSample:
    """A joint sample: ``seq`` counts up (videocal's protocol wraps it at 2^32), ``t_ms`` the controller's clock (ms),
    ``joints_deg`` (n,) deg or mm in the controller's axis order."""

    seq: int
    t_ms: int
    joints_deg: tuple[float, ...]


class LinkState(str, Enum):
    """``connecting``: opening or waiting for the first sample; ``up``: samples arrive;
    ``stale``: open but no sample within the watchdog time; ``down``: the device is gone
    (reconnecting with backoff); ``closed``: closed by the caller."""

    CONNECTING = "connecting"
    UP = "up"
    STALE = "stale"
    DOWN = "down"
    CLOSED = "closed"


@dataclass(frozen=True)
class TimedSample:
    """A joint sample with ``t_host_s``: the host's monotonic clock when its last byte arrived."""

    sample: JointSample
    t_host_s: float

    @property
    def joints_deg(self) -> tuple[float, ...]:
        return self.sample.joints_deg


@dataclass
class LinkStats:
    """Counters since the link started. Sentences: ``sentences`` verified, ``garbage_bytes``,
    ``bad_checksum``, ``too_long``, ``malformed`` (framing or fields), ``non_finite``,
    ``unknown`` types, ``wrong_joint_count`` (samples for another robot). Samples: ``samples`` delivered, ``seq_gaps``
    (times the sequence
    jumped) and ``missing_samples`` (how many it skipped), ``backwards_samples`` (a repeated or
    older sequence number or time: not delivered), ``controller_restarts`` (its clock went back over
    1 s, or to its first 0.5 s: counted, delivered). Link: ``reconnects``, ``errors`` (ERR replies, a DON without its
    ACK,
    callback failures)."""

    sentences: int = 0
    garbage_bytes: int = 0
    bad_checksum: int = 0
    too_long: int = 0
    malformed: int = 0
    non_finite: int = 0
    unknown: int = 0
    wrong_joint_count: int = 0
    samples: int = 0
    seq_gaps: int = 0
    missing_samples: int = 0
    reconnects: int = 0
    errors: int = 0
    backwards_samples: int = 0
    controller_restarts: int = 0

    def as_dict(self) -> dict[str, int]:
        return dict(self.__dict__)


class LinkError(VideocalError, RuntimeError):
    """The link could not be opened (an unusable URL or a missing device)."""


class MoveError(VideocalError, RuntimeError):
    """The controller refused or aborted a move; the message carries its ERR code and text."""


class MoveTimeout(MoveError):
    """No DON arrived for a move within its timeout."""


class MoveHandle:
    """Tracks one MVJ: ``acked`` once the controller accepted it; :meth:`wait` returns when it
    is done, or raises :class:`MoveError` / :class:`MoveTimeout`."""

    def __init__(self, move_id: str, joints_deg: tuple[float, ...], deadline_s: float):
        self.id = move_id
        self.joints_deg = joints_deg
        self.deadline_s = deadline_s
        self.acked = False
        self.sent = True  # False when the link could not send it (then it has finished with the reason)
        self.sent_s: float | None = None
        """When it was written to the controller (host monotonic s): its ACK times the round trip."""
        # A move's outcome is a future: it ends once, and a callback added after the end runs at once.
        self._outcome: Future = Future()

    @property
    def finished(self) -> bool:
        return self._outcome.done()

    @property
    def error(self) -> MoveError | None:
        """Why the move failed, once it has finished (``None`` while running or when it arrived)."""
        return self._outcome.exception() if self._outcome.done() else None

    def on_finished(self, callback) -> None:
        """``callback(handle)`` once the move has ended (done, refused, timed out), on the thread
        that ended it (the link's reader); at once if it has already ended."""
        self._outcome.add_done_callback(lambda _: callback(self))

    def _finish(self, error: MoveError | None = None) -> None:
        try:
            if error is None:
                self._outcome.set_result(None)
            else:
                self._outcome.set_exception(error)
        except InvalidStateError:  # ended already (a late ACK after a timeout): the first outcome stands
            pass

    def wait(self, timeout: float | None = None) -> None:
        """Block until the move is done (at most ``timeout`` s, then :class:`MoveTimeout`)."""
        try:
            self._outcome.result(timeout)
        except FutureTimeout:
            raise MoveTimeout(f"move {self.id}: still running after {timeout:g} s of waiting") from None
