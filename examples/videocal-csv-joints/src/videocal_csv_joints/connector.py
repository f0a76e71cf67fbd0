"""``csvjoints:///path/joints.csv``: joint samples played back from a CSV file, as a videocal controller connector.

The file: a header line, then ``t_ms,q1,...,qn`` per line (the robot's URDF joint order, deg or mm). Samples are
sent at the pace of their stamps, in order, each once; at the end of the file the link goes ``stale`` (no more
samples: videocal then says the pose is unknown). Moves are refused and never sent.
"""

from __future__ import annotations

import csv
import threading
import time
from pathlib import Path
from urllib.parse import unquote, urlsplit

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.events import ConnectorEvents
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkError, LinkState, LinkStats, MoveError, MoveHandle, TimedSample
from calib_core.link.protocol import JointSample


def _read(path: Path, n_joints: int) -> list[tuple[int, tuple[float, ...]]]:
    if not path.is_file():
        raise LinkError(f"csvjoints: no such file {path}")
    rows = []
    with path.open(newline="") as f:
        reader = csv.reader(f)
        next(reader, None)  # the header
        for number, row in enumerate(reader, start=2):
            try:
                t_ms, *q = (float(v) for v in row)
            except ValueError:
                raise LinkError(f"{path}, line {number}: numbers expected, got {row}") from None
            if len(q) != n_joints:
                raise LinkError(f"{path}, line {number}: {len(q)} joint values, the robot has {n_joints}")
            rows.append((int(t_ms), tuple(q)))
    if not rows:
        raise LinkError(f"{path}: no samples")
    return rows


class CsvJoints(ConnectorEvents):
    """The connector: the events (from :class:`ConnectorEvents`) and methods of
    :class:`calib_core.connectors.controller.ControllerConnector`."""

    def __init__(self, url: str, context: ControllerContext):
        self.url = url
        self.joint_map = JointMap.identity(context.n_joints)  # the file is in the model's joint order and zero
        self._rows = _read(Path(unquote(urlsplit(url).path)), context.n_joints)
        self.stats = LinkStats()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> CsvJoints:
        self._set_state(LinkState.CONNECTING, "opening the file")
        self._thread = threading.Thread(target=self._play, name=f"csvjoints {self.url}", daemon=True)
        self._thread.start()
        return self

    def _play(self) -> None:
        t0_host, t0_file = time.monotonic(), self._rows[0][0]
        for seq, (t_ms, q) in enumerate(self._rows):
            if self._stop.wait(max(0.0, (t_ms - t0_file) / 1000.0 - (time.monotonic() - t0_host))):
                return
            self.stats.samples += 1
            self._set_state(LinkState.UP, "playing the file")
            self._emit(self.sample_received, TimedSample(JointSample(seq, t_ms, q), time.monotonic()))
        self._set_state(LinkState.STALE, "the end of the file: no more samples")

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        self._set_state(LinkState.CLOSED, "closed by the caller")

    def move_joints(self, joints_deg, *, timeout_s: float = 60.0) -> MoveHandle:
        handle = MoveHandle("csv", tuple(joints_deg), time.monotonic())
        handle.sent = False
        handle._finish(MoveError("not sent: csvjoints plays back a file; it moves no robot"))
        return handle

    def stop(self) -> bool:
        return False

    def stats_snapshot(self) -> dict[str, int]:
        return self.stats.as_dict()


def open_csv_joints(url: str, context: ControllerContext) -> CsvJoints:
    """The entry point: ``open(url, context)``."""
    return CsvJoints(url, context)
