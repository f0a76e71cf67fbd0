"""The Universal Robots connector: ``ur-rtde://HOST`` (``?rate_hz=500&speed_deg_s=30``).

Joints come from RTDE through ``ur_rtde``'s ``RTDEReceiveInterface`` at the controller's rate (500 Hz on an
e-Series), each sample stamped with the controller's own ``timestamp`` (s since it started). Moves are URScript
``movej`` programs sent to the controller's secondary interface (port 30002) and Stop is ``stopj``: no program
has to be installed on the robot (``RTDEControlInterface`` uploads a control script of its own that takes the
robot over, docs/decisions/). A move is done when the joints stand within ``done_tolerance_deg`` of the target.

Shown to the operator (``status_changed``): protective stop, the speed slider (``speed_scaling``) and whether the
robot is in remote control (the dashboard server, port 29999); in a protective stop or local control a move is
not sent, and the message says why. The UR's joints are the URDF's in order (base, shoulder, elbow, wrist 1-3).

``ur_rtde`` holds Python's interpreter lock while it connects (a few round trips): the connector connects on its
own thread, and a simulated controller must run in another process (``videocal sim-ur``).
"""

from __future__ import annotations

import itertools
import math
import socket
import threading
import time
from urllib.parse import parse_qs

import numpy as np
from psygnal import Signal

from calib_core.connectors.urls import split_url
from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.options import number_option
from calib_core.connectors.events import ConnectorEvents, SingleMove
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import (
    LinkError,
    LinkState,
    LinkStats,
    MoveError,
    MoveHandle,
    MoveTimeout,
    TimedSample,
)
from calib_core.connectors.link_types import JointSample
from calib_core.link.round_trip import RoundTrip

SCRIPT_PORT, DASHBOARD_PORT = 30002, 29999
RTDE_PORT = 30004  # the controller's RTDE interface (UR's RTDE guide)
_VARIABLES = ["timestamp", "actual_q", "safety_status_bits", "speed_scaling", "robot_status_bits", "runtime_state"]
_OPTIONS = {"rate_hz", "speed_deg_s", "acceleration_deg_s2", "done_tolerance_deg", "stale_after_s"}
_PROTECTIVE_STOP_BIT = 1 << 2


class URRtdeController(ConnectorEvents):
    """See the module. ``status_changed(text)``: the controller's own state in words.

    Its public members are the connector protocol (start, close, latest, delay_s, stats_snapshot, move_joints, stop),
    the configuration read from its URL (speeds, tolerances, rate) and the controller's own status (protective stop,
    speed scaling, remote control) the status line shows."""

    status_changed = Signal(str)

    def __init__(self, url: str, context: ControllerContext):
        parts = split_url(url, LinkError)
        if not parts.hostname:
            raise LinkError(f"{url!r}: a UR controller is ur-rtde://HOST (its IP address or name)")
        host = parts.netloc.rsplit("@", 1)[-1]
        if "]:" in host if host.startswith("[") else ":" in host:
            # a port (or a malformed one, -1 or 99999) was given: it was silently replaced by UR's own
            raise LinkError(
                f"{url!r}: a UR controller serves on its fixed ports (RTDE {RTDE_PORT}, the secondary interface 30002, "
                "the dashboard 29999): give ur-rtde://HOST without a port"
            )
        if context.n_joints == 0:  # no cell (``monitor`` without --workcell): the UR's own six joints, in its order
            context = ControllerContext(
                tuple(f"joint_{k + 1}" for k in range(6)),
                ("deg",) * 6,
                JointMap.identity(6),
                context.rate_hz,
                context.options,
            )
        if context.n_joints != 6 or any(u != "deg" for u in context.joint_units):
            raise LinkError(
                f"{url}: a UR robot has 6 revolute joints; the cell's robot has {context.n_joints} "
                f"({', '.join(context.joint_units)})"
            )
        options = dict(context.options or {})
        options.update({k: v[-1] for k, v in parse_qs(parts.query).items()})
        unknown = set(options) - _OPTIONS
        if unknown:
            raise LinkError(
                f"{url!r}: unknown option(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_OPTIONS))}"
            )
        self.url = url
        self.host = parts.hostname
        self.rate_hz = number_option(options, "rate_hz", 500.0, 1.0, 500.0, "ur-rtde")
        self.speed_deg_s = number_option(options, "speed_deg_s", 30.0, 0.1, 180.0, "ur-rtde")
        self.acceleration_deg_s2 = number_option(options, "acceleration_deg_s2", 60.0, 1.0, 800.0, "ur-rtde")
        self.done_tolerance_deg = number_option(options, "done_tolerance_deg", 0.05, 1e-4, 10.0, "ur-rtde")
        self.stale_after_s = number_option(options, "stale_after_s", 0.5, 0.05, 60.0, "ur-rtde")
        self.n_joints = 6
        self.joint_map = JointMap.identity(6)
        self.stats = LinkStats()
        self.protective_stop = False
        self.speed_scaling = 1.0
        self.remote_control: bool | None = None
        self._latest: TimedSample | None = None
        self._moves = SingleMove()
        self._lock = threading.Lock()
        self._ids = itertools.count(1)
        self._seq = itertools.count()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._receive = None
        self._script: socket.socket | None = None
        self._dashboard_asked = threading.Event()
        self.round_trip = RoundTrip()
        """The round trip to the controller (s), timed on the dashboard's answers: its waits follow it."""

    # --- life cycle ----------------------------------------------------------------------------
    def start(self) -> URRtdeController:
        if self._thread is None:
            self._set_state(LinkState.CONNECTING, f"connecting to the UR controller at {self.host}")
            self._thread = threading.Thread(target=self._run, name=f"ur-rtde {self.host}", daemon=True)
            self._thread.start()
            # The pendant's mode is asked on a thread of its own: a far robot answers seconds later, and the
            # reader must not miss RTDE samples meanwhile.
            threading.Thread(target=self._watch_dashboard, name=f"ur-dashboard {self.host}", daemon=True).start()
        return self

    def close(self) -> None:
        if self._moves.current is not None and not self._moves.current.finished:
            self.stop()
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        receive, self._receive = self._receive, None
        if receive is not None:  # ended by us, before the controller's side goes: ur_rtde then prints no exception
            try:
                receive.disconnect()
            except RuntimeError:
                pass
        self._set_state(LinkState.CLOSED, "closed by the caller")
        self._moves.finish(MoveError("the link was closed"))

    @property
    def latest(self) -> TimedSample | None:
        return self._latest

    def stats_snapshot(self) -> dict[str, int]:
        with self._lock:
            return self.stats.as_dict()

    # --- commands ------------------------------------------------------------------------------
    def move_joints(self, joints_deg, *, timeout_s: float = 60.0) -> MoveHandle:
        q = np.array([float(v) for v in joints_deg])
        if len(q) != 6 or not np.all(np.abs(q) < 1e6):
            raise ValueError(f"a move needs 6 finite joint values, got {list(q)}")
        handle = MoveHandle(f"ur.{next(self._ids)}", tuple(q), time.monotonic() + timeout_s)
        why = self._why_not_sendable()
        program = (
            "def videocal_move():\n"
            f"  movej([{', '.join(f'{v:.6f}' for v in np.radians(q))}], "
            f"a={math.radians(self.acceleration_deg_s2):.4f}, v={math.radians(self.speed_deg_s):.4f})\n"
            "end\n"
        )
        if why is None:
            self._moves.begin(handle)
            why = self._send_script(program)
            if why is not None:
                self._moves.finish(MoveError(why))
        if why is not None:
            handle.sent = False
            if not handle.finished:
                handle._finish(MoveError(f"move {handle.id}: not sent: {why}"))
            return handle
        handle.acked = True
        return handle

    def stop(self) -> bool:
        """``stopj`` on the script port: the robot decelerates to a stand where it is."""
        sent = self._send_script(f"stopj({math.radians(4 * self.acceleration_deg_s2):.4f})\n") is None
        self._moves.finish(MoveError("ERR,STOPPED: stopped by the operator"))
        return sent

    def _why_not_sendable(self) -> str | None:
        if self._state is not LinkState.UP or self._latest is None:
            return f"the link is {self._state.value} (no fresh RTDE data from {self.host})"
        if not self._dashboard_asked.is_set():
            return (
                f"the dashboard server {self.host}:{DASHBOARD_PORT} has not said yet whether the robot is in remote "
                "control"
            )
        if self.protective_stop:
            return (
                "the robot is in a protective stop: clear it on the teach pendant (or the dashboard's 'unlock "
                "protective stop')"
            )
        if self.remote_control is False:
            return "the robot is in local control: switch it to remote control on the teach pendant"
        return None

    def _send_script(self, text: str) -> str | None:
        for attempt in range(2):  # a script socket the controller closed is opened again once
            try:
                if self._script is None:
                    self._script = socket.create_connection((self.host, SCRIPT_PORT), timeout=2.0)
                self._script.sendall(text.encode())
                return None
            except OSError as exc:
                if self._script is not None:
                    self._script.close()
                self._script = None
                if attempt:
                    return f"the script port {self.host}:{SCRIPT_PORT} refused it: {exc}"
        return None

    @property
    def delay_s(self) -> float | None:
        """The one-way delay to the controller (s): half the round trip of the dashboard's answers."""
        return self.round_trip.one_way_s()

    def _dashboard(self, command: str) -> str | None:
        """The dashboard server's answer to ``command`` (``None``: no answer). Its question and answer time the
        round trip; each wait is the round trip's timeout doubled (a far robot answers seconds later)."""
        try:
            with socket.create_connection((self.host, DASHBOARD_PORT), timeout=2.0 * self.round_trip.rto_s) as s:
                f = s.makefile("rwb")
                f.readline()  # the greeting
                asked = time.monotonic()
                f.write(command.encode() + b"\n")
                f.flush()
                answer = f.readline().decode(errors="replace").strip()
                if answer:
                    self.round_trip.add(time.monotonic() - asked)
                return answer
        except TimeoutError:
            self.round_trip.timed_out()
            return None
        except OSError:
            return None

    # --- the reader thread ---------------------------------------------------------------------
    def _connect(self) -> bool:
        import rtde_receive

        # ur_rtde prints "connect: Connection refused" on stderr at every failed try (C++, verbose or not): ahead of
        # the one error line, once per retry. A plain TCP connect first says the same thing quietly.
        try:
            with socket.create_connection((self.host, RTDE_PORT), timeout=2.0):
                pass
        except OSError as exc:
            self.last_error = f"cannot reach {self.host}:{RTDE_PORT}: {exc.strerror or exc}"
            self._receive = None
            return False
        try:
            self._receive = rtde_receive.RTDEReceiveInterface(self.host, self.rate_hz, _VARIABLES)
        except RuntimeError as exc:
            self.last_error = str(exc)
            self._receive = None
            return False
        return True

    def _watch_dashboard(self) -> None:
        while not self._stop.is_set():
            remote = self._dashboard("is in remote control")
            self._update_status(remote_control=None if remote is None else remote.lower() == "true")
            self._dashboard_asked.set()
            self._stop.wait(2.0)

    def _run(self) -> None:
        backoff = 0.2
        last_stamp = None
        last_new = time.monotonic()
        period = 1.0 / self.rate_hz
        while not self._stop.is_set():
            if self._receive is None or not self._receive.isConnected():
                self._set_state(
                    LinkState.DOWN if self._receive is not None or self.stats.reconnects else LinkState.CONNECTING,
                    f"no RTDE connection to {self.host}:{RTDE_PORT} ({self.last_error or 'connecting'})",
                )
                if self._stop.wait(backoff) or not self._connect():
                    backoff = min(backoff * 2, 2.0)
                    continue
                self.stats.reconnects += 1
                backoff = 0.2
            try:
                stamp = self._receive.getTimestamp()
                if stamp != last_stamp:
                    q = np.degrees(self._receive.getActualQ())
                    bits = int(self._receive.getSafetyStatusBits())
                    scaling = float(self._receive.getSpeedScaling())
                    last_stamp, last_new = stamp, time.monotonic()
                    self._on_sample(stamp, q, bits, scaling)
            except RuntimeError as exc:  # the connection broke under the call
                self.last_error = str(exc)
                self.stats.errors += 1
                self._receive = None
                continue
            now = time.monotonic()
            if self._state is LinkState.UP and now - last_new > self.stale_after_s + self.round_trip.spread_s:
                self._set_state(LinkState.STALE, f"no RTDE data for {now - last_new:.1f} s")
            move = self._moves.current
            if move is not None and now > move.deadline_s:
                self._moves.finish(MoveTimeout("the joints did not reach the target in time"))
            time.sleep(period / 2)

    def _on_sample(self, stamp_s: float, q: np.ndarray, safety_bits: int, scaling: float) -> None:
        t_ms = int(round(stamp_s * 1000))
        if self._latest is not None and t_ms <= self._latest.sample.t_ms:
            self.stats.backwards_samples += 1  # within the same millisecond as the last, or older: not the robot now
            return
        sample = TimedSample(JointSample(next(self._seq), t_ms, tuple(float(v) for v in q)), time.monotonic())
        with self._lock:
            self.stats.sentences += 1
            self.stats.samples += 1
            self._latest = sample
        if self._state is not LinkState.UP:
            self._set_state(LinkState.UP, "RTDE data arriving")
        self._update_status(protective_stop=bool(safety_bits & _PROTECTIVE_STOP_BIT), speed_scaling=scaling)
        self._emit(self.sample_received, sample)
        move = self._moves.current
        if move is not None:
            if self.protective_stop:
                self._moves.finish(MoveError("ERR,STOPPED: the robot went into a protective stop"))
            elif float(np.max(np.abs(q - np.asarray(move.joints_deg)))) <= self.done_tolerance_deg:
                self._moves.finish(None)

    def _update_status(self, **changes) -> None:
        before = (self.protective_stop, round(self.speed_scaling, 2), self.remote_control)
        for key, value in changes.items():
            setattr(self, key, value)
        if (self.protective_stop, round(self.speed_scaling, 2), self.remote_control) != before:
            self._emit(self.status_changed, self.status_text())

    def status_text(self) -> str:
        """``protective stop`` / ``speed 100 %`` / ``remote control`` or ``local control``."""
        parts = ["PROTECTIVE STOP"] if self.protective_stop else []
        parts.append(f"speed {self.speed_scaling * 100:.0f} %")
        if self.remote_control is not None:
            parts.append("remote control" if self.remote_control else "LOCAL control (moves not sent)")
        return ", ".join(parts)


def open_ur_rtde(url: str, context: ControllerContext) -> URRtdeController:
    """Entry point of ``videocal.controllers`` for ``ur-rtde://``."""
    return URRtdeController(url, context)
