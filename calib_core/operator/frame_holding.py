"""The frames picks are made on: the newest frame observed (live, or from a recording being replayed), the frame held
for a set of picks, and the robot state each was captured in.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.frames``), given the frames
(:class:`~calib_core.operator.observations.Observations`), the arm (when its last move was sent), the pairs (a still
no complete pair was picked on is let go) and the log. The first image pick of a set holds the newest frame, only
when the robot had settled before it; every image pick carries that frame's
:class:`~calib_core.calibration.view_stamp.ViewStamp`; pairs of two robot poses are refused
(:func:`refuse_mixed_poses`).
"""

from __future__ import annotations

import time

from calib_core.calibration.correspondences import CorrespondenceSet
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.errors import OperatorError
from calib_core.link.joint_history import JointHistory
from calib_core.operator.arm import Arm
from calib_core.operator.observations import HeldFrame, NotSettledError, Observations
from calib_core.operator.operator_log import OperatorLog


def refuse_mixed_poses(pairs, view: ViewStamp | None = None) -> None:
    """Raise :class:`CalibrationError` unless every one of ``pairs`` that carries a robot state was picked in
    ``view``'s (default: the first one's): one set of pairs comes from one robot pose."""
    stamped = [p for p in pairs if p.view is not None]
    reference = view or (stamped[0].view if stamped else None)
    if reference is None:
        return
    other = [p for p in stamped if not p.view.same_state(reference)]
    if other:
        worst = max(other, key=lambda p: p.view.joint_difference(reference))
        names = ", ".join(str(p.number) for p in other)
        raise CalibrationError(
            f"pair{'s' if len(other) > 1 else ''} {names} {'were' if len(other) > 1 else 'was'} picked with the "
            "robot at another pose "
            f"(a joint differs by {worst.view.joint_difference(reference):.2f} deg from {reference.label}): "
            "one set of pairs must come from one robot pose. Delete them (or Clear), or go back to that pose"
        )


class FrameHolding:
    """Which frame a pick is made on, and whether the robot stood still for it. Events (psygnal, the frames'):
    ``frame_observed(frame)``, ``still_changed(held or None)``.

    Fourteen public members: nine actions on the frames and, so that a view binds to this one model, the frames'
    two events and three of their states (``still``, ``latest``, ``replaying``) read through."""

    def __init__(self, observations: Observations, arm: Arm, pairs: CorrespondenceSet, log: OperatorLog):
        self._observations, self._arm, self._pairs, self._log = observations, arm, pairs, log
        self.frame_observed = observations.frame_observed
        self.still_changed = observations.still_changed
        pairs.changed.connect(self.release_unused_still)

    @property
    def still(self) -> HeldFrame | None:
        """The frame held for picking, or ``None`` (the live image)."""
        return self._observations.still

    @property
    def latest(self):
        """The newest frame observed, or ``None``."""
        return self._observations.latest

    @property
    def replaying(self) -> bool:
        return self._observations.replaying

    def observe_frame(self, frame, *, replayed: bool = False) -> None:
        """A camera frame arrived: from the camera (the window's worker, a command-line loop) or,
        with ``replayed``, from the recording being replayed. Live frames are ignored during a replay."""
        if self.replaying != replayed:
            return
        self._observations.observe(frame)

    def begin_replay(self, history: JointHistory, name: str) -> None:
        """A recording is being replayed: its frames and joints stand in for the live ones."""
        self._observations.replay(history, name)

    def end_replay(self) -> None:
        self._observations.go_live()

    def hold_frame(self) -> HeldFrame:
        """Hold the newest frame for picking (refused while the robot moves); ``still_changed``."""
        held = self._observations.hold()
        self._log.record(
            "frame_held",
            frame_index=held.stamp.frame_index,
            t_capture_s=held.stamp.t_capture_s,
            joints_deg=list(held.stamp.joints_deg),
        )
        return held

    def release_frame(self) -> None:
        """Back to the live image for picking (the pairs keep their stamps)."""
        self._observations.release()

    def release_unused_still(self, *_) -> None:
        """Back to the live image when no complete pair is picked on the held frame."""
        if self._observations.still is not None and not any(p.complete for p in self._pairs):
            self.release_frame()

    def stamp_for_pick(self, number: int) -> ViewStamp:
        """The robot state pair ``number``'s image point is picked in: the held frame's, holding the newest first;
        refused (:class:`CalibrationError`) when another complete pair was picked in another state."""
        held = self._observations.still
        if held is None:
            held = self.hold_frame()
        refuse_mixed_poses([p for p in self._pairs if p.complete and p.number != number], held.stamp)
        return held.stamp

    def frame_to_capture(self) -> tuple:
        """``(frame, stamp)`` for a board view: the newest frame (never a held still), by the same rule as
        a pick (the robot had settled before it; :class:`NotSettledError` otherwise) and taken after the
        last move was sent (a frame from before it shows the board from the pose before). ``stamp`` is
        ``None`` without a robot (no link, no replay): such a view serves the intrinsics only."""
        frame = self._observations.newest_usable()
        if frame is None:
            raise OperatorError("no camera frame yet: start the camera (Execute > Live) or open a recording")
        sent_s = self._arm.last_move_sent_s
        if not self.replaying and sent_s is not None and frame.t_host_s <= sent_s:
            raise NotSettledError(
                f"frame {frame.index} was taken before the last move ({self._arm.state.what}) was sent: wait for a "
                "frame from where the robot stands now"
            )
        has_robot = self.replaying or self._arm.link is not None
        return frame, (self._observations.stamp(frame) if has_robot else None)

    def robot_settled(self):
        """Whether the robot is still now (a :class:`~calib_core.link.joint_history.Stillness`), at the newest frame
        that can be judged (its joint samples arrived), or the newest sample's time."""
        obs = self._observations
        frame = obs.newest_usable()
        t = frame.t_host_s if frame is not None else obs.history.latest_s
        return obs.stillness_at(time.monotonic() if t is None else t)
