"""A recording seen at any instant: the camera frame, the joints, the point pairs and the last
solve as they were then. The window's replay timeline is a view of this; it has no Qt in it.

Times are seconds since the recording's first message (``0 .. duration_s``).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, replace

import numpy as np

from calib_core.calibration.correspondences import Correspondence, pair_from_dict
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.recording.frame_track import FrameTrack
from calib_core.recording.reader import RecordedMessage, RecordingContents
from calib_core.recording.schemas import EVENT_TOPIC, JOINTS_TOPIC, SETUP_TOPIC, SOLVE_TOPIC


@dataclass(frozen=True)
class RecordedSolve:
    """A solve as recorded: its ``inputs`` (re-solvable), ``result`` (``PoseSolution.to_dict``),
    ``context`` (obj2world, cam2world_model, tcp2base_model, joints; empty in older recordings)
    and ``t_s``."""

    id: int
    t_s: float
    inputs: dict
    result: dict
    context: dict


class RecordingPlayback:
    """Everything in a recording, indexed by time. ``name``: the recording's, which every pair it gives back carries
    as its frame's source (a look rebuilt from a recording is never taken for a live one)."""

    def __init__(self, contents: RecordingContents, name: str = "a recording"):
        self.contents = contents
        self.name = name
        self._t0 = contents.messages[0].log_time_ns if contents.messages else 0
        self.frames = FrameTrack(contents)
        joints = contents.topic(JOINTS_TOPIC)
        self.joint_times_s = np.array([self._t(m) for m in joints])
        rows = [m.payload["joints_deg"] for m in joints]
        if len({len(r) for r in rows}) > 1:
            raise ValueError(
                "the joint samples of the recording have "
                f"{' and '.join(str(n) for n in sorted({len(r) for r in rows}))} values"
            )
        # A recording of a camera alone has no joint samples: its frames replay, nothing is robot-bound.
        self.joints_deg = np.array(rows, dtype=float).reshape(len(rows), len(rows[0]) if rows else 0)
        self._events = [m for m in contents.topic(EVENT_TOPIC) if str(m.payload.get("kind", "")).startswith("pair_")]
        self._event_times = [self._t(m) for m in self._events]
        self.solves = [
            RecordedSolve(
                int(m.payload.get("id", k + 1)),
                self._t(m),
                m.payload["inputs"],
                m.payload["result"],
                m.payload.get("context") or {},
            )
            for k, m in enumerate(contents.topic(SOLVE_TOPIC))
        ]
        self._solve_times = [s.t_s for s in self.solves]
        setups = contents.topic(SETUP_TOPIC)
        self.setup: dict = setups[0].payload if setups else {}
        self.duration_s = self._t(contents.messages[-1]) if contents.messages else 0.0

    def _t(self, m: RecordedMessage) -> float:
        return (m.log_time_ns - self._t0) / 1e9

    def frame_index_at(self, t_s: float) -> int | None:
        """The frame shown at ``t_s``: the last one at or before it (``None`` without frames)."""
        if not len(self.frames):
            return None
        return self.frames.index_at(t_s)

    def joints_at(self, t_s: float) -> np.ndarray | None:
        """The last joint sample (deg) at or before ``t_s``; ``None`` before the first."""
        i = bisect.bisect_right(self.joint_times_s, t_s) - 1
        return None if i < 0 else self.joints_deg[i].copy()

    def pairs_at(self, t_s: float) -> list[Correspondence]:
        """The point pairs as they stood at ``t_s``, rebuilt from the recorded edits; each image point's view
        carries this recording as its source (recorded live, it is not live now)."""
        pairs: dict[int, Correspondence] = {}
        for m in self._events[: bisect.bisect_right(self._event_times, t_s)]:
            kind, d = m.payload["kind"], m.payload.get("detail", {})
            if kind in ("pair_added", "pair_changed") and "point_world_mm" in d:
                pair = pair_from_dict(d)
                if pair.pixel is not None and pair.view is None:
                    pair = replace(pair, view=self._view_at(self._t(m)))
                pairs[int(d["number"])] = pair
            elif kind == "pair_removed":
                pairs.pop(int(d["number"]), None)
            elif kind == "pair_reset":
                pairs = {int(p["number"]): pair_from_dict(p) for p in d.get("pairs", [])}
        return [self._recorded(p) for p in pairs.values()]

    def _recorded(self, pair: Correspondence) -> Correspondence:
        if pair.view is None or (pair.view.recorded and pair.view.source == self.name):
            return pair
        # a pair picked live is, replayed, a pair of this recording, whatever the recording's file is called
        return replace(pair, view=replace(pair.view, source=self.name, recorded=True))

    def _view_at(self, t_s: float) -> ViewStamp | None:
        """For a pair recorded without its frame stamp (older recordings): the frame shown and the
        recorded joints when its image point was picked."""
        q = self.joints_at(t_s)
        if q is None:
            return None
        i = bisect.bisect_right(self.joint_times_s, t_s) - 1
        k = self.frame_index_at(t_s)
        return ViewStamp(
            -1 if k is None else int(k),
            float(t_s),
            tuple(float(v) for v in q),
            float(t_s - self.joint_times_s[i]),
            f"{t_s:.3f} s into the recording",
            self.name,
        )

    def solve_at(self, t_s: float) -> RecordedSolve | None:
        """The last solve at or before ``t_s``."""
        i = bisect.bisect_right(self._solve_times, t_s) - 1
        return None if i < 0 else self.solves[i]
