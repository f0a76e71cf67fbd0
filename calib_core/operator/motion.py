"""What the robot is doing, in words: moving to a place, arrived, refused, or at an unknown pose.

The controller's answer to every move is awaited and kept here; a link that drops during a move
leaves the pose unknown until a fresh joint sample arrives.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from calib_core.connectors.link_types import MoveTimeout


class Motion(str, Enum):
    """``idle``: no move yet; ``moving``: a move was sent and has not ended; ``arrived``: the
    controller said done; ``refused``: it said no (limits, an error); ``failed``: no answer in time;
    ``unknown``: the link dropped, the robot may have moved unseen."""

    IDLE = "idle"
    MOVING = "moving"
    ARRIVED = "arrived"
    REFUSED = "refused"
    FAILED = "failed"
    UNKNOWN = "unknown"


@dataclass(frozen=True)
class MotionState:
    """``motion``, ``what`` (the move's target in words) and ``detail`` (the controller's reason)."""

    motion: Motion = Motion.IDLE
    what: str = ""
    detail: str = ""

    @property
    def text(self) -> str:
        m = self.motion
        if m is Motion.IDLE:
            return "robot: no move yet"
        if m is Motion.MOVING:
            return f"robot: moving to {self.what}"
        if m is Motion.ARRIVED:
            return f"robot: arrived at {self.what}"
        if m is Motion.REFUSED:
            return f"robot: move to {self.what} refused: {self.detail}"
        if m is Motion.FAILED:
            return f"robot: move to {self.what} failed: {self.detail}"
        return f"robot: pose unknown ({self.detail})"


def ended(what: str, error) -> MotionState:
    """The state after a move to ``what`` ended with ``error`` (``None``: done)."""
    if error is None:
        return MotionState(Motion.ARRIVED, what)
    text = str(error)
    if isinstance(error, MoveTimeout) or "nothing was sent" in text:
        return MotionState(Motion.FAILED, what, text)
    if "link was closed" in text:
        return MotionState(Motion.UNKNOWN, what, text)
    return MotionState(Motion.REFUSED, what, text)
