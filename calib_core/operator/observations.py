"""Camera frames bound to the robot state they were captured in.

Every frame the operator sees passes through here. A frame becomes usable for picks (and board
views) only with a :class:`~calib_core.calibration.view_stamp.ViewStamp`: the joints at its
capture time from the joint history, and proof that the robot had settled before it. The first
image pick of a set holds that frame (a still): the operator picks on it while the live video
goes on; every pick of the set carries the still's stamp.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone

from psygnal import Signal

from calib_core.calibration.view_stamp import ViewStamp
from calib_core.errors import OperatorError
from calib_core.link.joint_history import ControllerClock, JointHistory, Stillness
from calib_core.connectors.frame import Frame


RECENT_FRAMES = 16
"""The frames always kept to fall back on while the newest wait for their joint samples (at 15 fps, about a second)."""
RECENT_BYTES = 256 * 2**20
"""Beyond :data:`RECENT_FRAMES`, older frames are kept while they are younger than the joint stream can lag
(twice the link's spread of delays, plus half a second) and their pixels take no more than this (bytes)."""


class NotSettledError(OperatorError):
    """A frame cannot be used: the robot was moving, or its pose at the frame is unknown."""


@dataclass(frozen=True)
class HeldFrame:
    """A frame held for picking, with its stamp."""

    frame: Frame
    stamp: ViewStamp


class Observations:
    """The newest frame (``latest``), the held one (``still``) and the joint ``history`` that
    stamps them. ``source``: ``live``, or the name of the recording being replayed (then the
    history is the recording's, on its time axis). One object for the program's life: a replay
    swaps its source, so whoever listens keeps listening.

    Events (psygnal): ``frame_observed(frame)`` (every frame of the current source),
    ``still_changed(held)`` (a :class:`HeldFrame`, or ``None`` when let go; only on a change),
    ``source_changed(source)`` (``live`` or the recording's name).

    Its public members: three events, the frames' state (the live and the replayed joint history, the source, the newest
    and the held frame) and the rule that stamps a frame (stillness, stamp, newest usable), with hold, release, replay
    and live."""

    frame_observed = Signal(object)
    still_changed = Signal(object)
    source_changed = Signal(str)

    def __init__(self, live_history: JointHistory, live_clock: ControllerClock | None = None):
        self.live_history = live_history
        """The link's joints in time: written by every joint sample, replay or not."""
        self.live_clock = live_clock or ControllerClock()
        """Stamps the link's joint samples with their controller time; its spread is how much older than its stamp
        a live frame's content may be on the joints' time base."""
        self.history = live_history
        self._clock: ControllerClock | None = self.live_clock
        self.source = "live"
        """What the frames are called for people: ``live`` or the recording's name (which the user chose)."""
        self.live = True
        """Whether the frames come from the camera: the type of the source, never its name."""
        self.latest: Frame | None = None
        self._recent: deque[Frame] = deque()
        self._recent_bytes = 0
        self.still: HeldFrame | None = None

    @property
    def replaying(self) -> bool:
        return not self.live

    def observe(self, frame: Frame) -> None:
        """A frame of the current source arrived: ``frame_observed``."""
        self.latest = frame
        self._keep(frame)
        self.frame_observed.emit(frame)

    def _keep(self, frame: Frame) -> None:
        # By time, not by count: on a far link the joint samples of a frame arrive up to the link's spread later
        # than the frame, and a fixed count of frames at a high rate would all be waiting at once.
        self._recent.append(frame)
        self._recent_bytes += frame.image.nbytes
        window_s = 2.0 * self.margin_s + 0.5
        while len(self._recent) > RECENT_FRAMES:
            oldest = self._recent[0]
            if frame.t_host_s - oldest.t_host_s <= window_s and self._recent_bytes <= RECENT_BYTES:
                break
            self._recent.popleft()
            self._recent_bytes -= oldest.image.nbytes

    def replay(self, history: JointHistory, name: str) -> None:
        """A recording ``name`` stands in for the live source: its frames, stamped by its ``history``
        (on the recording's time axis, which has no link spread)."""
        self._switch(history, name, None, live=False)

    def go_live(self) -> None:
        """Back to the camera and the link's joints. Frames seen before the replay are not kept: their
        joints are minutes old by now."""
        self._switch(self.live_history, "live", self.live_clock, live=True)

    @property
    def margin_s(self) -> float:
        """How much older than its stamp a frame's content may be on the joints' time base (s): the link's spread
        (none for a recording's frames, stamped on the recording's own time axis)."""
        return 0.0 if self._clock is None else self._clock.spread_s

    def _switch(self, history: JointHistory, source: str, clock: ControllerClock | None, *, live: bool) -> None:
        self.release()
        self.history, self.source, self._clock, self.live = history, source, clock, live
        self.latest = None
        self._recent.clear()
        self._recent_bytes = 0
        self.source_changed.emit(source)

    def stillness(self, frame: Frame) -> Stillness:
        return self.stillness_at(frame.t_host_s)

    def stillness_at(self, t_s: float) -> Stillness:
        return self.history.stillness(t_s, self.margin_s)

    def stamp(self, frame: Frame) -> ViewStamp:
        """The frame's stamp; :class:`NotSettledError` when the robot was not still before it or
        its pose then is unknown."""
        still = self.stillness(frame)
        if not still.settled:
            raise NotSettledError(f"frame {frame.index} cannot be used: {still.reason}")
        at = self.history.joints_at(frame.t_host_s)
        if at is None:
            raise NotSettledError(f"frame {frame.index} cannot be used: no joint sample near its capture time")
        if self.live:
            age_s = max(0.0, time.monotonic() - frame.t_host_s)
            captured_at = (datetime.now(timezone.utc) - timedelta(seconds=age_s)).isoformat(timespec="milliseconds")
        else:
            captured_at = f"{frame.t_host_s:.3f} s into {self.source}"
        return ViewStamp(
            int(frame.index),
            float(frame.t_host_s),
            tuple(float(v) for v in at.joints_deg),
            float(at.stamp_gap_s),
            captured_at,
            self.source,
            recorded=not self.live,
        )

    def newest_usable(self) -> Frame | None:
        """The newest frame whose joint samples have arrived: the joint stream lags the frames by up to a sample
        period (20 ms at 50 Hz) on a near link, and by the link's spread of delays on a far one (most of a second at
        1.5 s +-30 %), so the newest frames may not be judged yet. The newest of all when none can be."""
        newest_sample_s = self.history.latest_s
        if newest_sample_s is not None:
            for frame in reversed(self._recent):
                if frame.t_host_s <= newest_sample_s:
                    return frame
        return self.latest

    def hold(self, frame: Frame | None = None) -> HeldFrame:
        """Hold ``frame`` for picking. By default the newest; when its joint samples have not arrived
        yet (the joint stream lags a frame by up to a sample period, 20 ms at 50 Hz), the one before
        it: a click on the image must not be refused for that."""
        if frame is None:
            frame = self.newest_usable()
        if frame is None:
            raise OperatorError("no camera image yet: start the camera (Execute > Live) or open a recording")
        self.still = HeldFrame(frame, self.stamp(frame))
        self.still_changed.emit(self.still)
        return self.still

    def release(self) -> None:
        """Let the held frame go (``still_changed(None)`` if one was held)."""
        if self.still is not None:
            self.still = None
            self.still_changed.emit(None)
