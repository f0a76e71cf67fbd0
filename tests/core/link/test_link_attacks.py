"""The link attacks: a heartbeat from anyone kept a move running after the workstation died, a
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

from calib_core.connectors.link_types import LinkState
from calib_core.link import auth
from calib_core.link.assembler import SentenceAssembler
from calib_core.link.driver import ControllerLink
from calib_core.link.protocol import MAX_SENTENCE_BYTES, Ack, ErrorReply, JointSample, encode, parse_body
from calib_core.link.workstation_auth import AuthState
from videocal_sim.controller_sim import ControllerLogic

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
        (reply,) = controller.handle(f"HEL,{nonce},{auth.hello_request(KEY, nonce)}")
        assert reply.proof == auth.controller_proof(KEY, nonce, reply.nonce, reply.clock_ms)
        assert controller.handle(f"AUT,{auth.workstation_proof(KEY, nonce, reply.nonce)}") == [Ack("AUT", "-")]
        self.session, self.counter = auth.session_key(KEY, nonce, reply.nonce), 0

    def seal(self, body: str, t_ms: int | None = None) -> str:
        """``body`` sealed now on the controller's clock (or at ``t_ms``)."""
        self.counter += 1
        return auth.seal(self.session, self.counter, self.c.clock_ms() if t_ms is None else t_ms, body)

    def sealed(self, body: str) -> list:
        return self.c.handle(self.seal(body))


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
    stranger = auth.new_nonce()
    (reply,) = c.handle(f"HEL,{stranger},{'0' * 32}")  # a second writer on the line, without the key
    assert reply.code == "AUTH" and reply.text.startswith(f"hello {stranger}: wrong request") and c.session_open
    assert c.handle("AUT," + "0" * 32)[0].text.startswith("auth: AUT without a HEL first")  # no offer was made to it
    assert c.session_open and ws.sealed("MVJ,a.1,10,0,0,0,0,0") == [Ack("MVJ", "a.1")]
    ws2 = _Workstation(c)  # a complete handshake (the workstation again, after a restart) replaces it
    assert ws.sealed("STP")[-1] == Ack("STP", "-")
    refused = ws.sealed("MVJ,a.2,0,0,0,0,0,0")
    assert refused[0].code == "AUTH" and "wrong seal" in refused[0].text
    assert ws2.sealed("MVJ,b.1,0,0,0,0,0,0") == [Ack("MVJ", "b.1")]


@pytest.mark.parametrize(
    "body",
    [
        "MVJ," + "m" * 250 + ",10,0,0,0,0,0",  # a keyless move with a long id
        "MVJ,x.1,1e308,-1e308,1e308,-1e308,1e308,-1e308",  # numbers whose refusal quotes 309 digits
        "MVJ,x.1," + ",".join(["1e308"] * 16),
    ],
)
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
    assert 20.0 < last < 160.0 and np.allclose(
        [x.joints_deg[0] for x in samples[-10:]], last
    )  # stopped short of its goal, at rest


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
        while squatter.recv(4096):  # the samples it heard while nobody held a session, then the end:
            pass  # it was let go when the workstation came (a recv that times out fails the test)


def test_a_sealed_move_held_back_by_a_relay_and_released_after_the_workstation_died_is_refused():
    """A keyless relay between the two passed heartbeats on late, withheld the first sealed move with the heartbeat
    before it, and released both after the workstation had died (8 s, then 20 s). Version 5 obeyed: joint 1 moved
    0 to 90 deg with nobody at the workstation. The seals now carry the time they were made."""
    for held_s in (8.0, 20.0):
        clock = _Clock()
        c = ControllerLogic(clock=clock, key=KEY)
        ws = _Workstation(c)
        assert ws.sealed("HBT,1000") == []
        heartbeat, move = ws.seal("HBT,1000"), ws.seal("MVJ,a.1,90,0,0,0,0,0")  # withheld by the relay
        clock.t += 3.0 + held_s  # the workstation is killed 3 s later; the relay waits, then releases them
        (late_heartbeat,) = c.handle(heartbeat)
        assert late_heartbeat.code == "AUTH" and "stale: sealed" in late_heartbeat.text
        (late_move,) = c.handle(move)
        assert late_move.code == "AUTH" and "stale: sealed" in late_move.text and c.move is None
        assert c.joints_deg[0] == 0.0
        assert parse_body(late_move.body()) == late_move  # the refusal crosses the line whole (one ERR text field)


def test_the_dead_man_counts_from_when_a_heartbeat_was_sealed_not_when_it_arrived():
    clock = _Clock()
    c = ControllerLogic(clock=clock, key=KEY)
    ws = _Workstation(c)
    assert ws.sealed("HBT,1000") == []
    assert ws.sealed("MVJ,a.1,160,0,0,0,0,0") == [Ack("MVJ", "a.1")]
    held = ws.seal("HBT,1000")  # sealed now, delivered 0.8 s late: it feeds the dead-man for 0.2 s, not 1 s
    clock.t += 0.8
    assert c.handle(held) == []
    clock.t += 0.25
    out = c.tick()
    assert out and out[0].code == "DEADMAN" and c.move is None


def test_a_move_released_after_the_dead_man_ran_out_is_refused_even_when_fresh_enough():
    """A session whose handshake took 4 s (a far link) allows seals 8.5 s old; a move held back 3 s is within that,
    but the last heartbeat's time has run out: the workstation is not there to stop it, and it is not started."""
    clock = _Clock()
    c = ControllerLogic(clock=clock, key=KEY)
    nonce = auth.new_nonce()
    (reply,) = c.handle(f"HEL,{nonce},{auth.hello_request(KEY, nonce)}")
    clock.t += 4.0
    assert (
        c.handle(f"AUT,{auth.workstation_proof(KEY, nonce, reply.nonce)}") == [Ack("AUT", "-")] and c.fresh_ms == 8500
    )
    session = auth.session_key(KEY, nonce, reply.nonce)
    assert c.handle(auth.seal(session, 1, c.clock_ms(), "HBT,1000")) == []
    move = auth.seal(session, 2, c.clock_ms(), "MVJ,a.1,90,0,0,0,0,0")
    clock.t += 3.0
    (refused,) = c.handle(move)
    assert refused.code == "DEADMAN" and c.move is None


def test_a_flood_of_keyless_hellos_leaves_the_workstation_s_handshake_alone_and_is_answered_sparingly():
    """A writer without the key sends a hello every 20 ms while the workstation connects (version 5 answered each,
    and the workstation's answer to its own hello no longer matched: 3 of 6 connects failed). Now only the key's
    holder is answered, the refusals at most 10 a second."""
    from calib_core.link.workstation_auth import WorkstationAuth
    from videocal_sim.controller_sim import REFUSALS_PER_S

    clock = _Clock()
    c = ControllerLogic(clock=clock, key=KEY)
    ws = WorkstationAuth(KEY)
    ours = ws.hello()
    answers = []
    for k in range(100):  # 2 s of flood, our hello in the middle of it
        clock.t += 0.02
        answers += c.handle(f"HEL,{auth.new_nonce()},{'0' * 32}")
        if k == 50:
            (reply,) = [r for r in c.handle(ours)]
            aut = ws.on_hello_reply(reply)
    assert all(isinstance(a, ErrorReply) and a.text.startswith("hello ") for a in answers)
    assert len(answers) <= 3 * REFUSALS_PER_S and c.refusals_unanswered >= 100 - 3 * REFUSALS_PER_S
    for a in answers:
        assert ws.on_error(a) and ws.state is AuthState.PENDING  # others' refusals: not ours
    assert c.handle(aut) == [Ack("AUT", "-")]
    ws.on_accepted()
    assert ws.state is AuthState.READY and c.session_open


def test_a_replayed_hello_of_the_workstation_is_not_answered_again():
    c = ControllerLogic(clock=_Clock(), key=KEY)
    nonce = auth.new_nonce()
    hello = f"HEL,{nonce},{auth.hello_request(KEY, nonce)}"
    assert len(c.handle(hello)) == 1
    assert c.handle(hello) == []  # from a capture: it opens nothing


def test_a_flood_of_unsealed_heartbeats_is_counted_not_answered_beyond_ten_a_second():
    clock = _Clock()
    c = ControllerLogic(clock=clock, key=KEY)
    ws = _Workstation(c)
    replies = []
    for _ in range(1000):  # 1 s of forged heartbeats every millisecond
        clock.t += 0.001
        replies += c.handle("HBT,60000")
    assert 1 <= len(replies) <= 11 and c.refusals == 1000
    assert len(c.auth_refusals) <= 200  # the latest kept: a flood does not grow the controller's memory
    assert ws.sealed("MVJ,a.1,10,0,0,0,0,0") == [Ack("MVJ", "a.1")]  # the workstation's move is obeyed at once


_WORKSTATION_BEHIND_RELAY = textwrap.dedent("""
    import sys
    from calib_core.link.driver import ControllerLink
    link = ControllerLink(sys.argv[1], rate_hz=20, deadman_ms=1000).start(wait_open=True)
    assert link.wait_for_samples(3, 10.0), "no samples"
    print("auth", link.auth_state.value, flush=True)
    link.move_joints((90.0, 0, 0, 0, 0, 0), timeout_s=60)
    print("sent", flush=True)
    import time
    time.sleep(60)
""")


@pytest.mark.parametrize("released_after_s", [8.0])
def test_a_relay_releasing_a_withheld_move_after_the_workstation_died_moves_nothing(sim, released_after_s):  # noqa: F811
    """Through the real simulator and the real driver (in a process of its own, killed): the relay passes heartbeats
    200 ms late, withholds the first sealed move with the heartbeat before it, drops the rest; the workstation is
    killed 3 s later and the relay releases the two 8 s after that."""
    from tests.core.link.withholding_relay import WithholdingRelay

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    sim("--tcp", str(port), "--joints", "0,0,0,0,0,0", link=False)
    relay = WithholdingRelay(port)
    ws = subprocess.Popen(
        [sys.executable, "-c", _WORKSTATION_BEHIND_RELAY, f"socket://127.0.0.1:{relay.port}"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert ws.stdout.readline().strip() == "auth ready"
        assert ws.stdout.readline().strip() == "sent"
        deadline = time.monotonic() + 10
        while not relay.withheld and time.monotonic() < deadline:
            time.sleep(0.01)
        assert [b.split(",")[0] for b in relay.withheld] == ["HBT", "MVJ"]
        time.sleep(3.0)
        os.kill(ws.pid, signal.SIGKILL)
        ws.wait(5)
        time.sleep(released_after_s)
        seen = len(relay.from_controller)
        relay.release()
        for _ in range(20):  # 2 s of asking for the joints
            relay.ask("RQJ")
            time.sleep(0.1)
        replies = [parse_body(b) for b in relay.from_controller[seen:]]
    finally:
        if ws.poll() is None:
            ws.kill()
        ws.stdout.close()
        relay.close()
    refusals = [r for r in replies if isinstance(r, ErrorReply)]
    assert any(r.code == "AUTH" and "stale: sealed" in r.text and r.text.startswith("move ") for r in refusals), (
        refusals
    )
    assert not any(isinstance(r, Ack) and r.cmd == "MVJ" for r in replies)
    samples = [r for r in replies if isinstance(r, JointSample)]
    assert len(samples) >= 10 and all(abs(s.joints_deg[0]) < 1e-6 for s in samples)  # joint 1 never left 0 deg


def test_an_error_naming_no_move_ends_no_move_and_one_naming_it_ends_that_one():
    """A second writer's refusal (``$STR,999``: a rate too high; an old-style hello) names no move: it once ended the
    oldest move waiting for its ACK, and the window said "refused" while the robot went on to the goal."""
    from calib_core.connectors.link_types import MoveError, MoveHandle
    from calib_core.link.move_book import MoveBook

    book = MoveBook()
    first, second = (
        MoveHandle("m1.1", (10.0,), time.monotonic() + 30),
        MoveHandle("m1.2", (20.0,), time.monotonic() + 30),
    )
    book.add(first)
    book.add(second)
    for foreign in (
        ErrorReply("RANGE", "stream rate 999 Hz above 250 Hz"),
        ErrorReply("AUTH", "hello 0123456789abcdef: wrong request: expected a nonce and a request"),
        ErrorReply("SYNTAX", "bad checksum"),
    ):
        assert book.refused(foreign) is False
    assert not first.finished and not second.finished
    assert book.refused(ErrorReply("LIMIT", "move m1.2: joint 1 beyond its limit")) is True
    assert second.finished and not first.finished
    with pytest.raises(MoveError, match="m1.2 refused"):
        second.wait(0)
    assert book.refused(ErrorReply("LIMIT", "move m9.9: not ours")) is False and not first.finished


def test_a_second_writer_s_refused_sentences_do_not_end_the_workstation_s_moves(sim):  # noqa: F811
    """The real driver against the simulated controller on a pty, a second writer on the same line sending a sentence
    that draws an error naming no move just before each of the workstation's moves (so the error arrives while the
    move waits for its ACK): every move is confirmed done where it went, none said refused."""
    s = sim("--pty")
    with ControllerLink(s.url, rate_hz=50) as workstation, serial.Serial(str(s.url), timeout=0) as other:
        # samples flow while the handshake is under way: wait for it, as a move does (it once lagged under load)
        assert workstation.wait_for_samples(3, 5.0) and workstation._auth.wait_settled(25.0) is AuthState.READY
        errors = workstation.stats.errors
        for k, (goal, foreign) in enumerate(
            ((8.0, "STR,999"), (-8.0, "HEL,0123456789abcdef"), (6.0, "STR,999"), (-6.0, "HEL,0123456789abcdef"))
        ):
            other.write(encode(foreign))
            move = workstation.move_joints((goal, 0, 0, 0, 0, 0), timeout_s=30)
            move.wait(30)  # raises MoveError had the foreign refusal ended it
            assert workstation.wait_for_samples(workstation.stats.samples + 2, 5.0)
            assert abs(workstation.latest.sample.joints_deg[0] - goal) < 0.5, k
        assert workstation.stats.errors >= errors + 4  # the foreign refusals did reach the workstation


def test_a_flood_of_old_style_hellos_does_not_stop_the_workstation_opening_its_session(sim):  # noqa: F811
    """A keyless writer on the line sending old-style two-field hellos every 20 ms (each draws
    ``ERR,SYNTAX,HEL with 1 fields``): the workstation took any error mentioning HEL during its handshake as a
    controller without authentication and gave up (3 of 6 connects). Every connect now opens its session and moves."""
    import threading

    s = sim("--pty")
    stop = threading.Event()

    def flood():
        with serial.Serial(str(s.url), timeout=0) as other:
            while not stop.is_set():
                other.write(encode("HEL,0123456789abcdef"))
                stop.wait(0.02)

    flooder = threading.Thread(target=flood, daemon=True)
    flooder.start()
    try:
        for k in range(4):
            with ControllerLink(s.url, rate_hz=50) as workstation:
                assert workstation.wait_for_samples(3, 5.0)
                assert workstation._auth.wait_settled(10.0) is AuthState.READY, (k, workstation.auth_failure)
                workstation.move_joints((2.0 * (k + 1), 0, 0, 0, 0, 0), timeout_s=20).wait(20)
    finally:
        stop.set()
        flooder.join(5)
