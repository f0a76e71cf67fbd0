"""A simulated Universal Robots controller: RTDE on port 30004 (as the RTDE guide specifies, so Universal Robots'
own client library, ``ur_rtde``, reads it), URScript on the secondary interface (port 30002: ``movej``, ``stopj``)
and a few dashboard-server commands (port 29999: ``is in remote control``, ``safetystatus``,
``unlock protective stop``). Joints move as synchronised trapezoids at the ``v`` a ``movej`` asks, scaled by the
speed slider (``speed_scaling``).

It reads no truth (it is the controller, not the world). Faults for tests: :meth:`protective_stop`, a local
(not remote) control mode that ignores scripts, the speed slider. Serve it on its own loopback address
(``127.0.0.2``...) to run several on one machine: the ports are the controller's fixed ones.
"""

from __future__ import annotations

import math
import re
import socket
import struct
import threading
import time

import numpy as np

from calib_core.link.joint_motion import TrapezoidMove
from videocal_sim import rtde_wire as wire

_MOVEJ = re.compile(r"movej\(\s*\[([^\]]*)\]\s*(?:,\s*a\s*=\s*([0-9.eE+-]+))?\s*(?:,\s*v\s*=\s*([0-9.eE+-]+))?")
_STOPJ = re.compile(r"stopj\(")


class SimulatedURController:
    """``initial_rad`` (6,); ``lower_rad``/``upper_rad`` the joint limits. ``host``: a loopback address."""

    def __init__(
        self, initial_rad, *, host: str = "127.0.0.1", lower_rad=None, upper_rad=None, version=(5, 11, 0, 0), log=None
    ):
        self.host = host
        self.version = version
        self.lower = np.asarray(lower_rad if lower_rad is not None else [-2 * math.pi] * 6, float)
        self.upper = np.asarray(upper_rad if upper_rad is not None else [2 * math.pi] * 6, float)
        self.q = np.asarray(initial_rad, float).copy()
        self.speed_slider = 1.0
        self.remote_control = True
        self.protective_stopped = False
        self.scripts: list[str] = []
        self.ignored_scripts = 0
        self.log = log or (lambda text: None)
        self._move: TrapezoidMove | None = None
        self._lock = threading.Lock()
        self._t0 = time.monotonic()
        self._stop = threading.Event()
        self._servers: list[socket.socket] = []
        self._threads: list[threading.Thread] = []

    # --- the robot -----------------------------------------------------------------------------
    def position(self, now: float | None = None) -> np.ndarray:
        now = time.monotonic() if now is None else now
        with self._lock:
            if self._move is None:
                return self.q.copy()
            q = np.radians(self._move.position(now))
            if self._move.finished(now):
                self.q, self._move = q, None
            return q

    def moving(self) -> bool:
        self.position()
        return self._move is not None

    def protective_stop(self) -> None:
        """As a collision would: the arm halts where it is; scripts are refused until unlocked."""
        with self._lock:
            pass
        q = self.position()
        with self._lock:
            self.q, self._move, self.protective_stopped = q, None, True

    def _movej(self, q_target: np.ndarray, v_rad_s: float) -> str | None:
        if self.protective_stopped:
            return "protective stop: not moving"
        if len(q_target) != 6 or not np.all(np.isfinite(q_target)):
            return f"movej needs 6 joint values, got {list(q_target)}"
        if np.any(q_target < self.lower) or np.any(q_target > self.upper):
            return "movej: a target joint is outside the limits"
        now = time.monotonic()
        start = np.degrees(self.position(now))
        speed = np.full(6, math.degrees(max(v_rad_s, 1e-3)) * self.speed_slider)
        with self._lock:
            self._move = TrapezoidMove.plan(start, np.degrees(q_target), speed, now)
        return None

    def _stopj(self) -> None:
        q = self.position()
        with self._lock:
            self.q, self._move = q, None

    def run_script(self, text: str) -> None:
        """A URScript program or line from the secondary interface (the subset this controller knows)."""
        if not self.remote_control:
            self.ignored_scripts += 1
            self.log("script ignored: the robot is in local control")
            return
        self.scripts.append(text)
        for line in text.splitlines():
            if _STOPJ.search(line):
                self._stopj()
            elif m := _MOVEJ.search(line):
                try:
                    q = np.array([float(v) for v in m.group(1).split(",")])
                except ValueError:
                    self.log(f"syntax error in movej: {line.strip()}")
                    continue
                why = self._movej(q, float(m.group(3) or 1.05))
                if why:
                    self.log(why)

    # --- RTDE ----------------------------------------------------------------------------------
    def _values(self, names: list[str]) -> list:
        q = self.position()
        moving = self._move is not None
        status_bits = 0b1 | (0b10 if moving else 0)
        safety_bits = 0b100 if self.protective_stopped else 0b1
        values = {
            "timestamp": time.monotonic() - self._t0,
            "actual_q": list(q),
            "target_q": list(q),
            "actual_qd": [0.0] * 6,
            "target_qd": [0.0] * 6,
            "target_qdd": [0.0] * 6,
            "actual_TCP_pose": [0.0] * 6,
            "target_TCP_pose": [0.0] * 6,
            "actual_execution_time": 0.1,
            "robot_mode": wire.ROBOT_MODE_RUNNING,
            "joint_mode": [253] * 6,
            "safety_mode": wire.SAFETY_MODE_PROTECTIVE_STOP if self.protective_stopped else wire.SAFETY_MODE_NORMAL,
            "safety_status": wire.SAFETY_MODE_PROTECTIVE_STOP if self.protective_stopped else wire.SAFETY_MODE_NORMAL,
            "speed_scaling": self.speed_slider,
            "target_speed_fraction": self.speed_slider,
            "runtime_state": wire.RUNTIME_STATE_PLAYING if moving else wire.RUNTIME_STATE_STOPPED,
            "robot_status_bits": status_bits,
            "safety_status_bits": safety_bits,
            "payload": 0.0,
        }
        return [
            values.get(name, 0) if wire.FORMATS[wire.OUTPUTS[name]][0] != "6" or name in values else [0] * 6
            for name in names
        ]

    def _serve_rtde(self, conn: socket.socket) -> None:
        recipe: list[str] = []
        frequency = 125.0
        streaming = threading.Event()
        send_lock = threading.Lock()

        def send(data: bytes) -> None:
            with send_lock:
                conn.sendall(data)

        def stream() -> None:
            types = [wire.OUTPUTS[n] for n in recipe]
            period = 1.0 / frequency
            next_s = time.monotonic()
            while streaming.is_set() and not self._stop.is_set():
                try:
                    send(wire.package(wire.DATA_PACKAGE, bytes([1]) + wire.pack_values(types, self._values(recipe))))
                except OSError:
                    return
                next_s += period
                delay = next_s - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                else:
                    next_s = (
                        time.monotonic() + period
                    )  # behind: skip ahead, never a burst (a controller's packages are a period apart)
                    time.sleep(period)

        try:
            while not self._stop.is_set():
                got = wire.read_package(conn)
                if got is None:
                    return
                kind, payload = got
                if kind == wire.REQUEST_PROTOCOL_VERSION:
                    send(wire.package(kind, bytes([1 if struct.unpack(">H", payload[:2])[0] in (1, 2) else 0])))
                elif kind == wire.GET_URCONTROL_VERSION:
                    send(wire.package(kind, struct.pack(">IIII", *self.version)))
                elif kind == wire.CONTROL_PACKAGE_SETUP_OUTPUTS:
                    frequency = min(max(struct.unpack(">d", payload[:8])[0], 1.0), 500.0)
                    # ur_rtde ends the list with a comma: an empty last name is no variable.
                    recipe = [n for n in payload[8:].decode().split(",") if n]
                    types = [wire.OUTPUTS.get(n, "NOT_FOUND") for n in recipe]
                    send(wire.package(kind, bytes([1]) + ",".join(types).encode()))
                elif kind == wire.CONTROL_PACKAGE_SETUP_INPUTS:
                    names = [n for n in payload.decode().split(",") if n]
                    send(wire.package(kind, bytes([1]) + ",".join("NOT_FOUND" for _ in names).encode()))
                elif kind == wire.CONTROL_PACKAGE_START:
                    ok = bool(recipe) and all(n in wire.OUTPUTS for n in recipe)
                    send(wire.package(kind, bytes([1 if ok else 0])))
                    if ok and not streaming.is_set():
                        streaming.set()
                        threading.Thread(target=stream, name="sim ur rtde stream", daemon=True).start()
                elif kind == wire.CONTROL_PACKAGE_PAUSE:
                    streaming.clear()
                    send(wire.package(kind, bytes([1])))
                elif kind == wire.DATA_PACKAGE:
                    pass  # inputs: none are in use here
        except OSError:
            return
        finally:
            streaming.clear()
            conn.close()

    # --- URScript and the dashboard --------------------------------------------------------------
    def _serve_script(self, conn: socket.socket) -> None:
        buffer = b""
        try:
            while not self._stop.is_set():
                chunk = conn.recv(65536)
                if not chunk:
                    return
                buffer += chunk
                # A program is "def ...: ... end"; a line outside one runs as it comes.
                while b"\n" in buffer:
                    text = buffer.decode(errors="replace")
                    if text.lstrip().startswith("def "):
                        end = re.search(r"\nend\s*\n", text)
                        if end is None:
                            break
                        program, buffer = text[: end.end()], text[end.end() :].encode()
                    else:
                        line, _, rest = text.partition("\n")
                        program, buffer = line, rest.encode()
                    self.run_script(program)
        except OSError:
            return
        finally:
            conn.close()

    def _serve_dashboard(self, conn: socket.socket) -> None:
        try:
            conn.sendall(b"Connected: Universal Robots Dashboard Server\n")
            for raw in conn.makefile("rb"):
                command = raw.decode(errors="replace").strip().lower()
                if command == "is in remote control":
                    reply = "true" if self.remote_control else "false"
                elif command == "safetystatus":
                    reply = "Safetystatus: PROTECTIVE_STOP" if self.protective_stopped else "Safetystatus: NORMAL"
                elif command == "unlock protective stop":
                    self.protective_stopped = False
                    reply = "Protective stop releasing"
                elif command == "robotmode":
                    reply = "Robotmode: RUNNING"
                else:
                    reply = f"could not understand: '{command}'"
                conn.sendall(reply.encode() + b"\n")
        except OSError:
            return
        finally:
            conn.close()

    # --- life cycle ----------------------------------------------------------------------------
    def start(
        self, rtde_port: int = 30004, script_port: int = 30002, dashboard_port: int = 29999
    ) -> SimulatedURController:
        for port, serve in (
            (rtde_port, self._serve_rtde),
            (script_port, self._serve_script),
            (dashboard_port, self._serve_dashboard),
        ):
            server = socket.create_server((self.host, port), reuse_port=False)
            server.settimeout(0.2)
            self._servers.append(server)
            thread = threading.Thread(target=self._accept, args=(server, serve), name=f"sim ur :{port}", daemon=True)
            thread.start()
            self._threads.append(thread)
        return self

    def _accept(self, server: socket.socket, serve) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = server.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            threading.Thread(target=serve, args=(conn,), daemon=True).start()

    def close(self) -> None:
        self._stop.set()
        for server in self._servers:
            server.close()
        for thread in self._threads:
            thread.join(timeout=1.0)
