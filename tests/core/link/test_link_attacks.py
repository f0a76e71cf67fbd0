"""Issue 32's link attacks: a heartbeat from anyone kept a move running after the workstation died, a
keyless HEL ended the workstation's session, a keyless TCP client locked it out, and long refusals made
the simulator exit. Each at the controller's logic and through the real simulator process."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
import serial

from calib_core.link import auth
from calib_core.link.assembler import SentenceAssembler
from calib_core.link.controller_sim import ControllerLogic
from calib_core.link.driver import ControllerLink
from calib_core.link.link_types import LinkState
from calib_core.link.protocol import MAX_SENTENCE_BYTES, Ack, ErrorReply, JointSample, encode, parse_body
from calib_core.link.workstation_auth import AuthState
from tests.core.link.test_link_with_simulator import sim  # noqa: F401 (the fixture)

KEY = bytes(range(32))


class _Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


class _Workstation:
    """The holder of the key, talking to a :class:`ControllerLogic` directly."""

    def __init__(self, controller: ControllerLogic):
        self.c = controller
        nonce = auth.new_nonce()
        (reply,) = controller.handle(f"HEL,{nonce}")
        assert controller.handle(f"AUT,{auth.workstation_proof(KEY, nonce, reply.nonce)}") == [Ack("AUT", "-")]
        self.session, self.counter = auth.session_key(KEY, nonce, reply.nonce), 0

    def sealed(self, body: str) -> list:
        self.counter += 1
        return self.c.handle(auth.seal(self.session, self.counter, body))


def test_an_unsealed_heartbeat_neither_keeps_a_move_running_nor_disarms_the_dead_man():
    clock = _Clock()
    c = ControllerLogic(clock=clock, key=KEY)
    ws = _Workstation(c)
    assert ws.sealed("HBT,500") == []  # armed by the workstation: 0.5 s
    assert ws.sealed("MVJ,a.1,160,0,0,0,0,0") == [Ack("MVJ", "a.1")]
    for _ in range(5):  # the workstation is gone; someone else sends heartbeats every 0.1 s
        clock.t += 0.1
        (refusal,) = c.handle("HBT,60000")
        assert refusal.code == "AUTH" and refusal.text == "heartbeat: not obeyed: the sentence carries no seal"
    clock.t += 0.15
    out = c.tick()
    assert out and out[0].code == "DEADMAN" and c.move is None and 0.0 < c.joints_deg[0] < 160.0
    assert c.deadman_s == 0.5  # nor did "HBT,0" from anyone disarm it
    c.handle("HBT,0")
    assert c.deadman_s == 0.5
    assert ws.sealed("HBT,0") == [] and c.deadman_s == 0.0  # the workstation may


def test_a_hello_without_the_key_does_not_end_the_workstations_session():
    c = ControllerLogic(clock=_Clock(), key=KEY)
    ws = _Workstation(c)
    (reply,) = c.handle(f"HEL,{auth.new_nonce()}")  # a second writer on the line
    assert reply.nonce and c.session_open
    assert c.handle("AUT," + "0" * 32)[0].text.startswith("auth: wrong proof")
    assert c.session_open and ws.sealed("MVJ,a.1,10,0,0,0,0,0") == [Ack("MVJ", "a.1")]
    ws2 = _Workstation(c)  # a complete handshake (the workstation again, after a restart) replaces it
    assert ws.sealed("STP")[-1] == Ack("STP", "-")
    refused = ws.sealed("MVJ,a.2,0,0,0,0,0,0")
    assert refused[0].code == "AUTH" and "wrong seal" in refused[0].text
    assert ws2.sealed("MVJ,b.1,0,0,0,0,0,0") == [Ack("MVJ", "b.1")]


@pytest.mark.parametrize("body", [
    "MVJ," + "m" * 250 + ",10,0,0,0,0,0",                         # a keyless move with a long id
    "MVJ,x.1,1e308,-1e308,1e308,-1e308,1e308,-1e308",             # numbers whose refusal quotes 309 digits
    "MVJ,x.1," + ",".join(["1e308"] * 16),
])
def test_every_refusal_fits_the_protocols_limit(body):
    for key in (KEY, None):
        c = ControllerLogic(clock=_Clock(), key=key)
        if key is not None:
            ws = _Workstation(c)
            replies = ws.sealed(body) if len(body) < 250 else c.handle(body)
        else:
            replies = c.handle(body)
        assert replies and all(isinstance(r, ErrorReply) for r in replies)
        for r in replies:
            assert len(encode(r.body())) <= MAX_SENTENCE_BYTES


def _raw_replies(port, seconds: float) -> list:
    assembler, out = SentenceAssembler(), []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        out += [parse_body(b) for b in assembler.feed(port.read(512))]
    return out


def test_the_simulator_survives_oversize_refusals(sim):  # noqa: F811
    s = sim("--pty", "--open")
    port = serial.serial_for_url(s.url, timeout=0.05)
    try:
        port.write(encode("MVJ," + "m" * 250 + ",10,0,0,0,0,0"))
        port.write(encode("MVJ,x.1,1e308,-1e308,1e308,-1e308,1e308,-1e308"))
        port.write(encode("RQJ"))
        replies = _raw_replies(port, 1.0)
    finally:
        port.close()
    assert s.proc.poll() is None, s.proc.stderr.read()
    assert [r.code for r in replies if isinstance(r, ErrorReply)][:2] == ["SYNTAX", "LIMIT"]
    assert any(isinstance(r, JointSample) for r in replies)


_WORKSTATION = textwrap.dedent("""
    import sys, time
    from calib_core.link.driver import ControllerLink
    link = ControllerLink(sys.argv[1], rate_hz=50, deadman_ms=300).start(wait_open=True)
    assert link.wait_for_samples(3, 5.0)
    link.move_joints((160.0, 0, 0, 0, 0, 0), timeout_s=30)
    while link.latest.joints_deg[0] < 20.0:
        time.sleep(0.01)
    print("moving", flush=True)
    time.sleep(60)
""")


def test_a_dead_workstation_s_move_stops_whatever_heartbeats_others_send(sim):  # noqa: F811
    s = sim("--pty", "--joints", "0,0,0,0,0,0")
    ws = subprocess.Popen([sys.executable, "-c", _WORKSTATION, s.url], stdout=subprocess.PIPE, text=True)
    try:
        assert ws.stdout.readline().strip() == "moving"
        os.kill(ws.pid, signal.SIGKILL)
        ws.wait(5)
        port = serial.serial_for_url(s.url, timeout=0.02)
        try:
            replies = []
            for _ in range(30):  # 3 s of someone else's heartbeats, every 0.1 s, asking for the joints too
                port.write(encode("HBT,60000"))
                port.write(encode("RQJ"))
                replies += _raw_replies(port, 0.1)
        finally:
            port.close()
    finally:
        if ws.poll() is None:
            ws.kill()
        ws.stdout.close()
    samples = [r for r in replies if isinstance(r, JointSample)]
    assert any(isinstance(r, ErrorReply) and r.code == "AUTH" and r.text.startswith("heartbeat:") for r in replies)
    last = samples[-1].joints_deg[0]
    assert 20.0 < last < 160.0 and np.allclose([x.joints_deg[0] for x in samples[-10:]], last)  # stopped short of its goal, at rest


def test_a_keyless_tcp_client_does_not_lock_the_workstation_out(sim):  # noqa: F811
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    sim("--tcp", str(port), link=False)
    with socket.create_connection(("127.0.0.1", port), timeout=5) as squatter:
        time.sleep(0.2)  # connected first, and stays
        with ControllerLink(f"socket://127.0.0.1:{port}", rate_hz=50) as workstation:
            assert workstation.wait_for_samples(3, 5.0) and workstation.state is LinkState.UP
            assert workstation.auth_state is AuthState.READY
            # and now that the workstation holds a session, a newcomer is turned away
            with socket.create_connection(("127.0.0.1", port), timeout=5) as intruder:
                intruder.sendall(encode("MVJ,x.1,90,0,0,0,0,0"))
                assert b"ERR,BUSY,another workstation is connected" in intruder.recv(4096)
            assert workstation.state is LinkState.UP
        squatter.settimeout(1.0)
        assert squatter.recv(4096) == b""  # it was let go when the workstation came
