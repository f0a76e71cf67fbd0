"""A bag's ``/tf`` and ``/tf_static`` as the flange's pose in time: for a robot whose joints are not in the bag, or
whose driver publishes its own kinematics (a controller's calibrated model) as the transforms.

The chain is walked from the flange frame up its parents to the base frame, as tf2 does, each link of it either
static (``/tf_static``, or a ``/tf`` edge sent once) or a stream interpolated at a stamp (translation linear,
rotation along the great circle). The time is each transform's header stamp, never the bag's record time. Written
here rather than taken from pytransform3d's ``TemporalTransformManager``, which would bring matplotlib and lxml
for a tree walk and a slerp.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.bags.joint_track import MAX_GAP_S
from calib_core.errors import FileFormatError
from calib_core.frames import concat, make_transform

TF_MESSAGE = "tf2_msgs/msg/TFMessage"


@dataclass(frozen=True)
class TfEdge:
    """``child2parent`` in time: ``stamps_ns`` (m,), ``xyz_mm`` (m, 3), ``quat_xyzw`` (m, 4); one sample: static."""

    parent: str
    child: str
    stamps_ns: np.ndarray
    xyz_mm: np.ndarray
    quat_xyzw: np.ndarray

    @property
    def static(self) -> bool:
        return len(self.stamps_ns) == 1

    def at(self, stamp_ns: int) -> np.ndarray | None:
        """``child2parent`` (4, 4) mm at ``stamp_ns``; ``None`` outside the stream or in a gap over ``MAX_GAP_S``."""
        if self.static:
            return make_transform(Rotation.from_quat(self.quat_xyzw[0]).as_matrix(), self.xyz_mm[0])
        t = self.stamps_ns
        k = int(np.searchsorted(t, stamp_ns, side="right"))
        if k == len(t) and t[-1] == stamp_ns:
            k -= 1
        if k == 0 or k == len(t) or t[k] - t[k - 1] > MAX_GAP_S * 1e9:
            return None
        f = (stamp_ns - t[k - 1]) / (t[k] - t[k - 1])
        r0, r1 = Rotation.from_quat(self.quat_xyzw[k - 1]), Rotation.from_quat(self.quat_xyzw[k])
        turn = Rotation.from_rotvec(f * (r0.inv() * r1).as_rotvec())
        return make_transform((r0 * turn).as_matrix(), self.xyz_mm[k - 1] + f * (self.xyz_mm[k] - self.xyz_mm[k - 1]))


@dataclass(frozen=True)
class TfTrack:
    """``flange2base`` in time through ``edges`` (from the flange up to the base)."""

    base: str
    flange: str
    edges: tuple[TfEdge, ...]

    def at(self, stamp_ns: int) -> np.ndarray | None:
        """``flange2base`` (4, 4) mm at ``stamp_ns``, or ``None`` where a streamed edge has no samples round it."""
        poses = [e.at(stamp_ns) for e in self.edges]
        return None if any(p is None for p in poses) else concat(*poses)

    def motion_around(self, stamp_ns: int, half_window_s: float) -> tuple[float, float] | None:
        """How far the flange moved (mm, deg from its pose at ``stamp_ns``) at every sample within ``half_window_s``
        either side; ``None`` when the window is not covered without a gap."""
        lo, hi = stamp_ns - int(half_window_s * 1e9), stamp_ns + int(half_window_s * 1e9)
        times = {lo, hi}
        for e in self.edges:
            if not e.static:
                times.update(int(t) for t in e.stamps_ns[(e.stamps_ns > lo) & (e.stamps_ns < hi)])
        here = self.at(stamp_ns)
        if here is None:
            return None
        moved_mm = moved_deg = 0.0
        for t in times:
            pose = self.at(t)
            if pose is None:
                return None
            moved_mm = max(moved_mm, float(np.linalg.norm(pose[:3, 3] - here[:3, 3])))
            moved_deg = max(
                moved_deg, float(np.degrees(Rotation.from_matrix(here[:3, :3].T @ pose[:3, :3]).magnitude()))
            )
        return moved_mm, moved_deg


STILL_MM, STILL_DEG = 0.05, 0.02
"""Still: the flange moved no more than this within the window (0.02 deg of a joint moves a flange 1 m out 0.35 mm;
the transforms carry the flange itself, so its own motion is held to the joints' angle and a twentieth of a mm)."""


def settled_flange(track: TfTrack, stamp_ns: int, half_window_s: float = 0.25) -> tuple[np.ndarray | None, str | None]:
    """(``flange2base`` at ``stamp_ns``, None) when the flange stood still round it; (None, why not) otherwise."""
    moved = track.motion_around(stamp_ns, half_window_s)
    if moved is None:
        return (
            None,
            f"no transform from {track.flange} to {track.base} all round it (within {half_window_s:g} s, no gap over "
            f"{MAX_GAP_S:g} s)",
        )
    if moved[0] > STILL_MM or moved[1] > STILL_DEG:
        return (
            None,
            f"the flange moved {moved[0]:.2f} mm, {moved[1]:.3f} deg within {half_window_s:g} s of it: not a still "
            "view",
        )
    return track.at(stamp_ns), None


def read_tf_track(path: str | Path, base: str, flange: str) -> TfTrack:
    """The flange's pose in the base from a bag's TFMessage topics (``/tf``, ``/tf_static`` and any other of that
    type). :class:`FileFormatError` names the bag when it has no transforms, or no chain from ``flange`` up to
    ``base`` (and says which frames it has)."""
    from calib_core.bags.bag_source import open_bag

    path = Path(path)
    samples: dict[str, tuple[str, list]] = {}  # child -> (parent, [(stamp, xyz, quat)])
    from calib_core.bags.bag_source import deserialize, messages

    with open_bag(path) as reader:
        connections = [c for c in reader.connections if c.msgtype == TF_MESSAGE]
        if not connections:
            held = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})) or "no messages"
            raise FileFormatError(
                path, f"no /tf in this bag (it holds {held}): the flange poses come from the transforms"
            )
        for connection, log_ns, raw in messages(reader, path, connections=connections):
            for tf in deserialize(reader, raw, connection, f"{path} {connection.topic}").transforms:
                parent, child = tf.header.frame_id.lstrip("/"), tf.child_frame_id.lstrip("/")
                stamp = tf.header.stamp.sec * 1_000_000_000 + tf.header.stamp.nanosec or log_ns
                t, q = tf.transform.translation, tf.transform.rotation
                xyz, quat = np.array([t.x, t.y, t.z]) * 1000.0, np.array([q.x, q.y, q.z, q.w])
                if not (np.all(np.isfinite(xyz)) and np.all(np.isfinite(quat))) or np.linalg.norm(quat) < 1e-9:
                    continue
                if child in samples and samples[child][0] != parent:
                    raise FileFormatError(
                        path,
                        f"the frame {child!r} has two parents in /tf ({samples[child][0]!r} and {parent!r}): tf2 would "
                        "refuse this tree",
                    )
                rows = samples.setdefault(child, (parent, []))[1]
                if connection.topic == "/tf_static":
                    rows.clear()  # latched: the newest one holds, whatever its stamp
                rows.append((stamp, xyz, quat / np.linalg.norm(quat)))
    chain, frame = [], flange
    while frame != base:
        if frame not in samples:
            frames = sorted(set(samples) | {p for p, _ in samples.values()})
            raise FileFormatError(
                path,
                f"no chain of transforms from {flange!r} up to {base!r} in /tf (it stops at {frame!r}; frames: "
                f"{', '.join(frames)}): "
                "name them with --base-frame and --flange-frame",
            )
        parent, rows = samples[frame]
        rows.sort(key=lambda r: r[0])
        stamps = np.array([r[0] for r in rows], dtype=np.int64)
        keep = np.concatenate([[True], np.diff(stamps) > 0])
        chain.append(
            TfEdge(
                parent, frame, stamps[keep], np.array([r[1] for r in rows])[keep], np.array([r[2] for r in rows])[keep]
            )
        )
        frame = parent
        if len(chain) > len(samples):
            raise FileFormatError(path, f"the transforms above {flange!r} form a loop")
    return TfTrack(base, flange, tuple(chain))
