"""The link attacks against the real simulator process, timed: a dead workstation's move
fed by someone else's heartbeats, a second writer's handshake, a keyless TCP squatter, oversize fields.
Used by bench/reliability_bench.py."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import serial

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.driver import ControllerLink
from calib_core.link.protocol import MAX_SENTENCE_BYTES, ErrorReply, JointSample, encode, parse_body

_WORKSTATION = textwrap.dedent("""
    import sys, time
    from calib_core.link.driver import ControllerLink
    link = ControllerLink(sys.argv[1], rate_hz=50, deadman_ms=1000).start(wait_open=True)
    link.wait_for_samples(3, 5.0)
    link.move_joints((160.0, 0, 0, 0, 0, 0), timeout_s=30)
    while link.latest.joints_deg[0] < 20.0:
        time.sleep(0.01)
    print("moving", flush=True)
    time.sleep(60)
""")


class _Simulator:
    def __init__(self, *args: str):
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "app.cli.main", "sim-controller", "--robot", "plain", *args],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        self.url = self.proc.stdout.readline().strip()

    def stop(self) -> None:
        self.proc.terminate()
        self.proc.wait(5)
        self.proc.stdout.close()


def _replies(port, seconds: float) -> list:
    assembler, out = SentenceAssembler(), []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        out += [(time.perf_counter(), parse_body(b)) for b in assembler.feed(port.read(512))]
    return out


def dead_workstation_with_foreign_heartbeats() -> dict:
    """SIGKILL the workstation mid-move (dead-man 1000 ms), then send ``HBT,60000`` unsealed every 100 ms:
    seconds from the kill to the robot at rest, and where it stopped of 160 deg."""
    with tempfile.TemporaryDirectory() as tmp:
        sim = _Simulator("--pty", "--link", str(Path(tmp) / "controller"), "--joints", "0,0,0,0,0,0")
        ws = subprocess.Popen([sys.executable, "-c", _WORKSTATION, sim.url], stdout=subprocess.PIPE, text=True)
        try:
            ws.stdout.readline()
            os.kill(ws.pid, signal.SIGKILL)
            killed = time.perf_counter()
            ws.wait(5)
            port = serial.serial_for_url(sim.url, timeout=0.02)
            seen = []
            try:
                for _ in range(40):
                    port.write(encode("HBT,60000"))
                    port.write(encode("RQJ"))
                    seen += _replies(port, 0.1)
            finally:
                port.close()
        finally:
            if ws.poll() is None:
                ws.kill()
            ws.stdout.close()
            sim.stop()
    samples = [(t, m.joints_deg[0]) for t, m in seen if isinstance(m, JointSample)]
    final = samples[-1][1]
    at_rest = next(t for t, q in samples if abs(q - final) < 1e-6)
    refused = sum(1 for _, m in seen if isinstance(m, ErrorReply) and m.text.startswith("heartbeat:"))
    return {"stopped_s": at_rest - killed, "stopped_deg": final, "refused": refused}


def second_writer_handshake() -> dict:
    """A keyless HEL and a wrong AUT on the workstation's pty: is the workstation's next move obeyed?"""
    with tempfile.TemporaryDirectory() as tmp:
        sim = _Simulator("--pty", "--link", str(Path(tmp) / "controller"), "--joints", "0,0,0,0,0,0")
        try:
            with ControllerLink(sim.url, rate_hz=50) as link:
                link.wait_for_samples(3, 5.0)
                intruder = serial.serial_for_url(sim.url, timeout=0.05)
                intruder.write(encode("HEL,0123456789abcdef," + "0" * 32))  # a hello without the key
                intruder.write(encode("AUT," + "0" * 32))
                time.sleep(0.3)
                intruder.close()
                started = time.perf_counter()
                link.move_joints((5.0, 0, 0, 0, 0, 0), timeout_s=10).wait(10)
                return {"obeyed": True, "move_s": time.perf_counter() - started}
        except Exception as exc:  # reported, not hidden
            return {"obeyed": False, "why": str(exc)}
        finally:
            sim.stop()


def tcp_squatter() -> dict:
    """A keyless client connects first and stays: seconds for the workstation to get its session."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    sim = _Simulator("--tcp", str(port))
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            time.sleep(0.2)
            started = time.perf_counter()
            with ControllerLink(f"socket://127.0.0.1:{port}", rate_hz=50) as link:
                link.wait_for_samples(3, 5.0)
                return {"state": link.auth_state.value, "session_s": time.perf_counter() - started}
    finally:
        sim.stop()


def oversize_fields() -> dict:
    """A 250-character move id and an MVJ of +-1e308: the longest reply and whether the simulator lives."""
    with tempfile.TemporaryDirectory() as tmp:
        sim = _Simulator("--pty", "--open", "--link", str(Path(tmp) / "controller"))
        try:
            port = serial.serial_for_url(sim.url, timeout=0.05)
            try:
                port.write(encode("MVJ," + "m" * 250 + ",10,0,0,0,0,0"))
                port.write(encode("MVJ,x.1,1e308,-1e308,1e308,-1e308,1e308,-1e308"))
                port.write(encode("RQJ"))
                seen = _replies(port, 1.0)
            finally:
                port.close()
            alive = sim.proc.poll() is None
        finally:
            sim.stop()
    longest = max(len(encode(m.body())) for _, m in seen)
    return {"alive": alive, "longest_reply": longest, "limit": MAX_SENTENCE_BYTES}
