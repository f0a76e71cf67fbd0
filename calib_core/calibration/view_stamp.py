"""What a 2D pick was made on: one camera frame, and the robot's joints when it was captured.

A pick without its robot state is a trap: solved with the joints of another moment, the same
pixels give a camera pose hundreds of millimetres off. Every image point carries its
:class:`ViewStamp`; a solve takes the joints from it, never the robot's current ones.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SAME_STATE_DEG = 0.02
"""Two views show one robot state when no joint differs by more than this (deg, or mm for a
prismatic joint): a still robot's encoder noise, far below what moves a pixel."""


@dataclass(frozen=True)
class ViewStamp:
    """``frame_index``: the frame's number in its source; ``t_capture_s``: its capture time on the
    joint history's clock (host monotonic s, or s on a recording's time axis); ``joints_deg`` (n,):
    the model joints at that time, interpolated from the link's samples (deg, mm prismatic);
    ``stamp_gap_s``: the distance from the capture to the nearest joint sample; ``captured_at``:
    the wall-clock time (ISO 8601, UTC) for people and files; ``source``: ``live`` or the recording's
    name."""

    frame_index: int
    t_capture_s: float
    joints_deg: tuple[float, ...]
    stamp_gap_s: float
    captured_at: str = ""
    source: str = "live"
    recorded: bool = False
    """Whether the frame came from a recording (``source`` then names it, for people): a type, never the name's
    spelling, since a user names a recording's file as they like (one named ``live`` is still a recording)."""

    def same_state(self, other: ViewStamp, tolerance_deg: float = SAME_STATE_DEG) -> bool:
        return self.joint_difference(other) <= tolerance_deg

    def joint_difference(self, other: ViewStamp) -> float:
        """The largest joint difference to ``other`` (deg/mm); ``inf`` for another joint count."""
        a, b = np.asarray(self.joints_deg), np.asarray(other.joints_deg)
        return float(np.max(np.abs(a - b))) if a.shape == b.shape else float("inf")

    @property
    def label(self) -> str:
        return f"frame {self.frame_index}" + (f" of {self.captured_at}" if self.captured_at else "")

    def to_dict(self) -> dict:
        return {
            "frame_index": self.frame_index,
            "t_capture_s": self.t_capture_s,
            "joints_deg": list(self.joints_deg),
            "stamp_gap_s": self.stamp_gap_s,
            "captured_at": self.captured_at,
            "source": self.source,
            "recorded": self.recorded,
        }

    @classmethod
    def from_dict(cls, d: dict) -> ViewStamp:
        """The inverse of :meth:`to_dict`; raises ``KeyError``/``TypeError``/``ValueError`` on a bad dict
        (the file readers turn those into errors naming the field)."""
        joints = tuple(float(v) for v in d["joints_deg"])
        if not joints or not all(np.isfinite(joints)):
            raise ValueError("joints_deg must be a non-empty list of finite numbers")
        return cls(
            int(d["frame_index"]),
            float(d["t_capture_s"]),
            joints,
            float(d.get("stamp_gap_s", 0.0)),
            str(d.get("captured_at", "")),
            str(d.get("source", "live")),
            # (files written before the flag: only a recording's name other than "live" says so)
            bool(d["recorded"]) if "recorded" in d else str(d.get("source", "live")) != "live",
        )
