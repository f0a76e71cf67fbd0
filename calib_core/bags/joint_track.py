"""A bag's ``sensor_msgs/JointState`` stream as a track of the arm's joints in time: read once, asked at any stamp.

Joints are taken by the cell's URDF joint names, in whatever order and company a message lists them (a gripper's
own states are not the arm's); radians and metres become degrees and millimetres. The time is the header stamp
(the robot's clock, the one the images' stamps are on), never the bag's record time. Asked at a stamp, the track
interpolates between the samples around it; it answers only where samples lie close on both sides, and says
whether the arm stood still over a window round it (a frame taken while the arm moved is no view for a
calibration: the flange pose at its stamp is a guess of the camera's exposure time).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from calib_core.errors import FileFormatError

JOINT_STATE = "sensor_msgs/msg/JointState"
MAX_GAP_S = 0.1
"""Samples further apart than this around a stamp leave the joints there unknown."""


@dataclass(frozen=True)
class JointTrack:
    """``stamps_ns`` (m,) increasing, ``joints`` (m, n) deg or mm, of ``topic``."""

    topic: str
    stamps_ns: np.ndarray
    joints: np.ndarray

    def at(self, stamp_ns: int) -> np.ndarray | None:
        """The joints (n,) at ``stamp_ns``, linear between the samples around it; ``None`` outside the track or in a
        gap."""
        t = self.stamps_ns
        k = int(np.searchsorted(t, stamp_ns, side="right"))
        if k == 0 or k == len(t):
            return self.joints[k - 1].copy() if k == len(t) and t[-1] == stamp_ns else None
        t0, t1 = t[k - 1], t[k]
        if (t1 - t0) > MAX_GAP_S * 1e9:
            return None
        f = (stamp_ns - t0) / (t1 - t0)
        return self.joints[k - 1] + f * (self.joints[k] - self.joints[k - 1])

    def motion_around(self, stamp_ns: int, half_window_s: float) -> float | None:
        """How far (deg or mm, the largest joint's range) the joints moved within ``half_window_s`` either side of
        ``stamp_ns``; ``None`` when the track does not cover that window without a gap."""
        lo, hi = stamp_ns - int(half_window_s * 1e9), stamp_ns + int(half_window_s * 1e9)
        t = self.stamps_ns
        i, j = int(np.searchsorted(t, lo, side="left")), int(np.searchsorted(t, hi, side="right"))
        if i == 0 or j == len(t):
            return None  # the window reaches past the track's ends
        window = t[i - 1 : j + 1]
        if np.max(np.diff(window)) > MAX_GAP_S * 1e9:
            return None
        q = self.joints[i - 1 : j + 1]
        return float(np.max(q.max(axis=0) - q.min(axis=0)))


SETTLE_HALF_WINDOW_S = 0.25
"""A frame's joints are taken only when the arm stood still this long either side of its stamp."""
STILL = 0.02
"""Still: no joint moved more than this (deg, or mm for a prismatic joint) within the window."""


def settled_joints(
    track: JointTrack, stamp_ns: int, half_window_s: float = SETTLE_HALF_WINDOW_S, still: float = STILL
) -> tuple[np.ndarray | None, str | None]:
    """(the joints at ``stamp_ns``, None) when the arm stood still round it; (None, why not) otherwise."""
    moved = track.motion_around(stamp_ns, half_window_s)
    if moved is None:
        return (
            None,
            f"no joint states on {track.topic} all round it (within {half_window_s:g} s, no gap over {MAX_GAP_S:g} s)",
        )
    if moved > still:
        return None, f"the arm moved {moved:.2f} deg (or mm) within {half_window_s:g} s of it: not a still view"
    return track.at(stamp_ns), None


def read_joint_track(path: str | Path, joint_names, per_si, topic: str | None = None) -> JointTrack:
    """The arm's joints from a bag's JointState topic (``topic``, else the only one, else ``/joint_states``).
    ``per_si`` (n,): deg per rad or mm per m for each joint. :class:`FileFormatError` names the bag for no such topic,
    or no message with all of the arm's joints (and says which names it had)."""
    from calib_core.bags.bag_source import deserialize, messages, open_bag

    names = list(joint_names)
    per_si = np.asarray(per_si, dtype=float)
    path = Path(path)
    with open_bag(path) as reader:
        candidates = [c for c in reader.connections if c.msgtype == JOINT_STATE]
        if topic is not None:
            candidates = [c for c in candidates if c.topic == topic]
        topics = sorted({c.topic for c in candidates})
        if not topics:
            held = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})) or "no messages"
            raise FileFormatError(
                path,
                f"no JointState topic{' ' + topic if topic else ''} in this bag (it holds {held}): the flange poses "
                "come from the joints",
            )
        if len(topics) > 1:
            chosen = "/joint_states" if "/joint_states" in topics else None
            if chosen is None:
                raise FileFormatError(
                    path, f"several JointState topics: choose one with --joint-topic: {', '.join(topics)}"
                )
            candidates = [c for c in candidates if c.topic == chosen]
        stamps, rows, seen_names = [], [], set()
        for connection, log_ns, raw in messages(reader, path, connections=candidates):
            message = deserialize(reader, raw, connection, f"{path} {connection.topic}")
            listed = list(message.name)
            seen_names.update(listed)
            if len(message.position) != len(listed):
                continue
            index = {n: i for i, n in enumerate(listed)}
            if any(n not in index for n in names):
                continue  # another group's states
            q = np.array([message.position[index[n]] for n in names], dtype=float) * per_si
            if not np.all(np.isfinite(q)):
                continue
            stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
            stamps.append(stamp or log_ns)
            rows.append(q)
    if not rows:
        raise FileFormatError(
            path,
            f"no JointState message on {candidates[0].topic} names all of the arm's joints ({', '.join(names)}); "
            f"it names {', '.join(sorted(seen_names)) or 'none'}: is it this cell's robot?",
        )
    order = np.argsort(np.asarray(stamps), kind="stable")
    stamps_ns = np.asarray(stamps, dtype=np.int64)[order]
    joints = np.asarray(rows)[order]
    keep = np.concatenate([[True], np.diff(stamps_ns) > 0])  # one sample per stamp
    return JointTrack(candidates[0].topic, stamps_ns[keep], joints[keep])
