"""The robot's recent joint history, from the link's time-stamped samples: where the robot was when a
camera frame was captured, and whether it had been still long enough before it for the frame and
the joints to agree.

Times are one clock: the host's monotonic seconds for a live link (``TimedSample.t_host_s`` and
``Frame.t_host_s``), seconds on the recording's time axis in a replay. Joints are the model's (deg
for revolute joints, mm for prismatic ones).
"""

from __future__ import annotations

import bisect
from collections import deque
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SettleRule:
    """The robot counts as still when, for ``hold_s`` seconds up to the frame's capture, no joint
    leaves a band of ``speed_deg_s * hold_s`` (deg, or mm for a prismatic joint): slower than
    ``speed_deg_s`` on average, and blind to sample-time jitter and encoder noise. ``max_gap_s``: the
    longest gap between samples that still counts as known motion (a longer one: the pose is
    unknown in between)."""

    speed_deg_s: float = 0.5
    hold_s: float = 0.3
    max_gap_s: float = 0.25


@dataclass(frozen=True)
class Stillness:
    """Whether the robot was settled at a time: ``settled``; ``reason`` says why not (empty when
    settled); ``still_for_s``: how long it had been still up to that time; ``speed_deg_s``: the
    fastest joint speed in the hold window (deg/s or mm/s) and ``joint`` its index (``None`` when
    no sample covers the window)."""

    settled: bool
    reason: str
    still_for_s: float
    speed_deg_s: float = 0.0
    joint: int | None = None
    pending: bool = False
    """Not judged yet: the samples around the time have not arrived (a frame newer than the newest sample)."""


@dataclass(frozen=True)
class JointsAt:
    """The joints (n,) deg/mm at a time, interpolated between the samples around it;
    ``stamp_gap_s``: the distance from that time to the nearest sample."""

    joints_deg: np.ndarray
    stamp_gap_s: float


class ControllerClock:
    """Maps the controller's sample clock to the host's. A sample's host arrival time is its send
    time plus a delay that varies (serial buffering, a reader thread that waits for the CPU); the
    smallest ``t_host - t_controller`` seen is the best estimate of the clock offset (the delay of
    the fastest sample), so ``t_controller + offset`` stamps every sample as it was sent, free of
    the reader's jitter. A controller clock that jumps back (a restart) starts the estimate again.
    ``delay_s`` is the last sample's arrival delay over that, the stamp difference kept per sample."""

    SPREAD_WINDOW_S = 10.0
    """How far back :attr:`spread_s` looks (s)."""

    def __init__(self, drift_allowance: float = 1e-4):
        self._recent: deque[tuple[float, float]] = deque()  # (host arrival s, delay over the fastest s)
        self.offset_s: float | None = None
        self._last_controller_s: float | None = None
        self._last_host_s: float | None = None
        self.drift_allowance = drift_allowance
        self.delay_s = 0.0
        self.restarts = 0

    def stamp(self, t_host_s: float, t_controller_s: float) -> float:
        """The host time at which the controller sent a sample stamped ``t_controller_s``."""
        if self._last_controller_s is not None and t_controller_s < self._last_controller_s:
            self.offset_s = None
            self.restarts += 1
        offset = t_host_s - t_controller_s
        if self.offset_s is not None and self._last_host_s is not None:
            # The two clocks drift apart slowly: let the estimate rise by a little over time.
            self.offset_s += self.drift_allowance * max(0.0, t_host_s - self._last_host_s)
        if self.offset_s is None or offset < self.offset_s:
            self.offset_s = offset
        self._last_controller_s, self._last_host_s = t_controller_s, t_host_s
        self.delay_s = offset - self.offset_s
        self._recent.append((t_host_s, self.delay_s))
        while self._recent and t_host_s - self._recent[0][0] > self.SPREAD_WINDOW_S:
            self._recent.popleft()
        return t_controller_s + self.offset_s

    @property
    def spread_s(self) -> float:
        """The largest arrival delay over the fastest one in the last :data:`SPREAD_WINDOW_S` (s): how far a
        frame that crossed the same link, stamped on arrival, may sit from the joints of its capture (a near link:
        milliseconds; a relay satellite's: a large part of a second)."""
        return max((d for _, d in self._recent), default=0.0)


class JointHistory:
    """The last ``keep_s`` seconds of joint samples, oldest first. :meth:`forget` marks the pose as
    unknown (the link dropped): nothing before it is used again."""

    def __init__(self, keep_s: float = 30.0, rule: SettleRule | None = None, joint_names: list[str] | None = None):
        self.keep_s = float(keep_s)
        self.rule = rule or SettleRule()
        self.joint_names = list(joint_names or [])
        self._t: deque[float] = deque()
        self._q: deque[np.ndarray] = deque()
        self.unknown_since_s: float | None = None
        """Set when the pose became unknown (``forget``); cleared by the next sample."""

    @classmethod
    def from_arrays(
        cls, times_s, joints_deg, rule: SettleRule | None = None, joint_names: list[str] | None = None
    ) -> JointHistory:
        """A whole recorded history: ``times_s`` (n,) s, non-decreasing; ``joints_deg`` (n, j)."""
        history = cls(keep_s=float("inf"), rule=rule, joint_names=joint_names)
        for t, q in zip(np.asarray(times_s, float), np.asarray(joints_deg, float)):
            history.add(t, q)
        return history

    def __len__(self) -> int:
        return len(self._t)

    @property
    def latest_s(self) -> float | None:
        return self._t[-1] if self._t else None

    def add(self, t_s: float, joints_deg) -> None:
        """A sample at ``t_s``; one older than the newest is dropped (the history stays in order)."""
        if self._t and t_s < self._t[-1]:
            return
        self._t.append(float(t_s))
        self._q.append(np.array(joints_deg, dtype=float))
        self.unknown_since_s = None
        while self._t and self._t[-1] - self._t[0] > self.keep_s:
            self._t.popleft()
            self._q.popleft()

    def forget(self, t_s: float) -> None:
        """The link dropped at ``t_s``: the robot may have moved without a word; the pose is unknown
        until a fresh sample arrives, and no earlier sample vouches for a later frame."""
        self._t.clear()
        self._q.clear()
        self.unknown_since_s = float(t_s)

    def joints_at(self, t_s: float) -> JointsAt | None:
        """The joints at ``t_s``, or ``None`` when no sample lies within ``max_gap_s`` of it."""
        if not self._t:
            return None
        times = self._t
        i = bisect.bisect_left(times, t_s)
        gap_before = t_s - times[i - 1] if i > 0 else np.inf
        gap_after = times[i] - t_s if i < len(times) else np.inf
        gap = min(gap_before, gap_after)
        if gap > self.rule.max_gap_s:
            return None
        if i == 0:
            return JointsAt(self._q[0].copy(), gap)
        if i == len(times):
            return JointsAt(self._q[-1].copy(), gap)
        t0, t1 = times[i - 1], times[i]
        w = 0.0 if t1 <= t0 else (t_s - t0) / (t1 - t0)
        return JointsAt((1 - w) * self._q[i - 1] + w * self._q[i], gap)

    def stillness(self, t_s: float, margin_s: float = 0.0) -> Stillness:
        """Whether the robot was still for ``rule.hold_s`` up to ``t_s``, from the samples. ``margin_s`` (s): how much
        older than ``t_s`` the frame's content may be on the joints' time base (a frame stamped on arrival that
        crossed a far link: :attr:`ControllerClock.spread_s`); the robot must then have been still from
        ``t_s - hold_s - margin_s`` to ``t_s``."""
        held = self._stillness(t_s, self.rule.hold_s + margin_s, self.rule.max_gap_s + margin_s)
        if margin_s >= 0.005 and not held.settled and held.reason.startswith("the robot was moving"):
            return Stillness(
                False,
                held.reason
                + f" (the frame may be up to {margin_s:.2f} s older than it says: the link's spread of delays)",
                held.still_for_s,
                held.speed_deg_s,
                held.joint,
            )
        return held

    def _stillness(self, t_s: float, hold_s: float, unknown_after_s: float) -> Stillness:
        rule = self.rule
        if not self._t:
            why = (
                "the link dropped: the robot's pose is unknown until a fresh joint sample arrives"
                if self.unknown_since_s is not None
                else "no joint samples: the robot's pose is unknown (is the controller link up?)"
            )
            return Stillness(False, why, 0.0)
        times = np.fromiter(self._t, float)
        if t_s - times[-1] > unknown_after_s:
            return Stillness(
                False,
                f"no joint sample in the {t_s - times[-1]:.2f} s before the frame: the robot's pose at the frame is "
                "unknown",
                0.0,
            )
        if t_s < times[0]:
            return Stillness(False, "the frame is older than the joint history: its robot pose is unknown", 0.0)
        if times[-1] < t_s:
            # Judged before the samples around the capture have arrived, a frame would be judged on older ones.
            return Stillness(
                False,
                f"waiting for the joint samples of the frame's time (the newest is {t_s - times[-1]:.2f} s older)",
                0.0,
                pending=True,
            )
        end = bisect.bisect_right(self._t, t_s)  # samples at or before the capture
        stop = min(end + 1, len(times))  # and the one after it: the motion across the capture counts
        q = np.array([self._q[k] for k in range(stop)])
        band = rule.speed_deg_s * rule.hold_s
        # Walk back from the capture while every joint stays within a band of speed x hold and the samples
        # have no gap: a displacement test, blind to how the samples' times jitter.
        lo = hi = q[stop - 1]
        k = stop - 1
        while k > 0:
            if times[k] - times[k - 1] > rule.max_gap_s:
                break
            new_lo, new_hi = np.minimum(lo, q[k - 1]), np.maximum(hi, q[k - 1])
            if np.any(new_hi - new_lo > band):
                break
            lo, hi, k = new_lo, new_hi, k - 1
        still_for = max(0.0, t_s - times[k])
        if still_for + 1e-9 >= hold_s:
            return Stillness(True, "", still_for)
        if k == 0:
            return Stillness(
                False,
                f"the joint history is only {still_for:.2f} s old at the frame ({hold_s:.2g} s of stillness needed)",
                still_for,
            )
        if times[k] - times[k - 1] > rule.max_gap_s:
            return Stillness(
                False,
                f"the joint samples stop for {times[k] - times[k - 1]:.2f} s {still_for:.2f} s before the frame: the "
                "robot may have moved unseen",
                still_for,
            )
        # moving: the fastest joint speed in the hold window, over sample pairs >= 0.1 s apart
        first = max(0, bisect.bisect_left(self._t, t_s - hold_s) - 1)
        speed, joint = 0.0, 0
        for a in range(first, stop - 1):
            b = bisect.bisect_left(self._t, times[a] + 0.1, lo=a + 1, hi=stop)
            b = min(b, stop - 1)
            if times[b] > times[a]:
                v = np.abs(q[b] - q[a]) / (times[b] - times[a])
                if v.max() > speed:
                    speed, joint = float(v.max()), int(np.argmax(v))
        when = "when the frame was taken" if still_for < 0.05 else f"{still_for:.2f} s before the frame"
        return Stillness(
            False,
            f"the robot was moving {when} ({self._name(joint)} at {speed:.2f} deg/s; settled means under "
            f"{rule.speed_deg_s:g} deg/s for {rule.hold_s:g} s)",
            still_for,
            speed,
            joint,
        )

    def _name(self, joint: int) -> str:
        return self.joint_names[joint] if joint < len(self.joint_names) else f"joint {joint + 1}"
