"""The status line's model: the robot's motion and link, whether a frame can be picked on, the pairs, a recording."""

from __future__ import annotations

from collections.abc import Callable

from calib_core.calibration.session import CalibrationSession
from calib_core.operator.arm import Arm
from calib_core.operator.frame_holding import FrameHolding
from calib_core.operator.session_recording import SessionRecording


class StatusLineModel:
    """What the status line reports: the robot's motion and its link (``link()``: the controller's link now, or
    ``None``; the window's link changes when it connects), whether the newest frame can be picked on (the settle rule),
    the usable pairs against those a solve needs, the recording being written.

    Its public members: five events it shows (``motion_changed``, ``link_state``, ``pairs_changed``,
    ``result_changed``, ``target_changed``), the link, and six read-outs the line polls once a second (rates, ages)."""

    def __init__(
        self,
        arm: Arm,
        session: CalibrationSession,
        frames: FrameHolding,
        recording: SessionRecording,
        link: Callable[[], object],
    ):
        self._arm, self._session, self._frames, self._recording = arm, session, frames, recording
        self.link = link
        self.motion_changed = arm.motion_changed
        self.link_state = arm.link_state
        self.pairs_changed = session.pairs.changed
        self.result_changed = session.result.changed
        self.target_changed = session.target_changed

    @property
    def last_sample_s(self) -> float | None:
        """When the last joint sample came (``time.monotonic()`` s), or ``None``."""
        return self._arm.last_sample_s

    @property
    def replaying(self) -> bool:
        return self._frames.replaying

    def robot_settled(self):
        """Whether the robot has been still long enough to pick on its frames (``settled``, ``reason``,
        ``still_for_s``)."""
        return self._frames.robot_settled()

    @property
    def usable_pairs(self) -> int:
        return len(self._session.pairs.usable())

    @property
    def required_pairs(self) -> int:
        return self._session.options.required_pairs

    @property
    def recorder(self):
        """The recorder writing the session (its ``size_bytes``), or ``None``."""
        return self._recording.recorder
