"""The shipped controller program (resources/controller/videocal_link.pdl), translated from its PDL2
subset and run as the controller on a pty against the workstation's real driver: its SHA-256 and HMAC
against the standard's vectors, its handshake, its sealed moves, its refusals and its stop."""

from __future__ import annotations

import hashlib
import hmac
import os
import select
import threading
import time
import tty
from pathlib import Path

import numpy as np
import pytest

from calib_core.link import auth
from calib_core.link.driver import ControllerLink
from calib_core.link.joint_motion import TrapezoidMove
from calib_core.connectors.link_types import MoveError
from calib_core.link.protocol import PROTOCOL_VERSION, parse_body
from calib_core.link.workstation_auth import AuthState

from tests.controller.pdl2_subset import load
from tests.core.link.raw_link import first_error_reply

PROGRAM = Path(__file__).resolve().parents[2] / "resources" / "controller" / "videocal_link.pdl"
KEY = bytes(range(100, 132))


class _Halt(Exception):
    pass


class ProgramOnPty:
    """The translated program as a controller: its SITE routines bound to a pty, the host clock and
    a simulated six-axis arm moving at 90 deg/s."""

    def __init__(self, key: bytes = KEY):
        self.master, slave = os.openpty()
        tty.setraw(slave)
        tty.setraw(self.master)
        self.path = os.ttyname(slave)
        self._slave = slave
        self.stop_flag = False
        self.t0 = time.monotonic()
        self.q = np.zeros(6)
        self.move: TrapezoidMove | None = None
        self.key = key
        site = {
            "configure": self._configure,
            "link_read": self._read,
            "link_write": self._write,
            "now_ms": self._now_ms,
            "boot_text": lambda: f"boot {self.t0:.6f}",
            "arm_joint": lambda j: float(self._position()[j - 1]),
            "arm_start": self._start,
            "arm_moving": lambda: self.move is not None and not self.move.finished(time.monotonic()),
            "arm_stop": self._stop_arm,
        }
        self.ns = load(PROGRAM.read_text(), site)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.failure: BaseException | None = None
        self.thread.start()

    def _configure(self):
        self.ns["link_key_hex"] = self.key.hex()
        self.ns["n_joints"] = 6
        for j in range(1, 7):
            self.ns["lower_deg"][j], self.ns["upper_deg"][j] = -170.0, 170.0

    def _read(self) -> int:
        if self.stop_flag:
            raise _Halt
        ready, _, _ = select.select([self.master], [], [], 0.002)
        return os.read(self.master, 1)[0] if ready else -1

    def _write(self, text: str) -> None:
        os.write(self.master, text.encode("ascii"))

    def _now_ms(self) -> int:
        return int((time.monotonic() - self.t0) * 1000)

    def _position(self):
        return self.move.position(time.monotonic()) if self.move is not None else self.q

    def _start(self):
        goal = np.array(self.ns["goal_deg"][1:7], dtype=float)
        self.move = TrapezoidMove.plan(self._position(), goal, np.full(6, 90.0), time.monotonic())

    def _stop_arm(self):
        self.q, self.move = np.array(self._position()), None

    def _run(self):
        try:
            self.ns["_main"]()
        except _Halt:
            pass
        except BaseException as exc:  # kept for the test to report
            self.failure = exc

    def close(self):
        self.stop_flag = True
        self.thread.join(5)
        for fd in (self.master, self._slave):
            os.close(fd)
        if self.failure is not None:
            raise self.failure


@pytest.fixture
def program():
    p = ProgramOnPty()
    yield p
    p.close()


@pytest.mark.parametrize("length", [0, 3, 55, 56, 63, 64, 65, 119, 200, 440])
def test_its_sha256_is_the_standards(length):
    site = {
        n: (lambda *a: None)
        for n in (
            "configure",
            "link_read",
            "link_write",
            "now_ms",
            "boot_text",
            "arm_joint",
            "arm_start",
            "arm_moving",
            "arm_stop",
        )
    }
    ns = load(PROGRAM.read_text(), site)
    ns["sha_constants"]()
    data = bytes((7 * i + 3) % 256 for i in range(length))
    ns["msg"][1 : length + 1] = list(data)
    ns["msg_len"] = length
    ns["sha256"]()
    assert bytes(ns["digest"][1:33]).hex() == hashlib.sha256(data).hexdigest()


@pytest.mark.parametrize(
    "key, data, expected",
    [
        (
            b"\x0b" * 20,
            "Hi There",
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7",
        ),  # RFC 4231 test case 1
        (
            b"Jefe",
            "what do ya want for nothing?",
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843",
        ),  # test case 2
    ],
)
def test_its_hmac_meets_rfc_4231(key, data, expected):
    site = {
        n: (lambda *a: None)
        for n in (
            "configure",
            "link_read",
            "link_write",
            "now_ms",
            "boot_text",
            "arm_joint",
            "arm_start",
            "arm_moving",
            "arm_stop",
        )
    }
    ns = load(PROGRAM.read_text(), site)
    ns["sha_constants"]()
    ns["key_bytes"][1:33] = list(key.ljust(32, b"\0"))  # a short key is zero-padded, as HMAC does
    ns["hmac"](data, False)
    assert ns["digest_hex"](64) == expected == hmac.new(key, data.encode(), hashlib.sha256).hexdigest()


def test_the_driver_opens_a_session_and_moves_the_arm(program):
    with ControllerLink(program.path, rate_hz=50, key=KEY).start(wait_open=True) as link:
        assert link.auth_state is AuthState.READY, link.auth_failure
        assert link.request_version(2.0).version == PROTOCOL_VERSION
        link.move_joints((20.0, -10.0, 5.0, 0.0, 30.0, -45.5), timeout_s=10).wait(10)
        assert link.wait_for_samples(link.stats.samples + 3, 2)
        assert link.latest.joints_deg == pytest.approx((20.0, -10.0, 5.0, 0.0, 30.0, -45.5), abs=1e-4)
        with pytest.raises(MoveError, match="LIMIT"):
            link.move_joints((200.0, 0, 0, 0, 0, 0), timeout_s=5).wait(5)
        running = link.move_joints((100.0, 0, 0, 0, 0, 0), timeout_s=10)
        assert link.wait_for_samples(link.stats.samples + 5, 2) and link.stop()
        with pytest.raises(MoveError, match="STOPPED"):
            running.wait(5)
        assert link.wait_for_samples(link.stats.samples + 3, 2)
        assert 20.0 < link.latest.joints_deg[0] < 99.0  # stopped on the way
        assert link.stats_snapshot()["bad_checksum"] == 0


def test_it_refuses_a_wrong_key_and_an_unsealed_move(program):
    with ControllerLink(program.path, rate_hz=20, key=bytes(32)).start(wait_open=True) as intruder:
        assert intruder.auth_state is AuthState.FAILED and "does not hold" in intruder.auth_failure
    err = first_error_reply(program.path, "MVJ,x1,10,0,0,0,0,0")
    assert err.code == "AUTH" and err.text == "move x1: not obeyed: no authenticated session (send HEL and AUT first)"
    assert program.move is None


class _ProgramBySentence:
    """The translated program fed one sentence body at a time on a clock the test sets (no pty)."""

    def __init__(self):
        self.t_ms, self.sent, self.q, self.moving = 0, [], np.zeros(6), False
        site = {
            "configure": self._configure,
            "link_read": lambda: -1,
            "link_write": self.sent.append,
            "now_ms": lambda: self.t_ms,
            "boot_text": lambda: "boot 1",
            "arm_joint": lambda j: float(self.q[j - 1]),
            "arm_start": self._start,
            "arm_moving": lambda: self.moving,
            "arm_stop": self._stop,
        }
        self.ns = load(PROGRAM.read_text(), site)
        self.ns["startup"]()

    def _configure(self):
        self.ns["link_key_hex"] = KEY.hex()
        self.ns["n_joints"] = 6
        for j in range(1, 7):
            self.ns["lower_deg"][j], self.ns["upper_deg"][j] = -170.0, 170.0

    def _start(self):
        self.moving = True

    def _stop(self):
        self.moving = False

    def handle(self, body: str) -> list:
        self.sent.clear()
        self.ns["handle"](body)
        return [parse_body(s[1 : s.index("*")]) for s in self.sent]

    def tick(self) -> list:
        self.sent.clear()
        self.ns["tick"]()
        return [parse_body(s[1 : s.index("*")]) for s in self.sent]


def _session(program: _ProgramBySentence, round_trip_ms: int = 0):
    """A session opened by the key's holder (its answer ``round_trip_ms`` after the hello); a function that seals a
    body at the program's clock now (or at ``t_ms``) and hands it over."""
    nonce = auth.new_nonce()
    (reply,) = program.handle(f"HEL,{nonce},{auth.hello_request(KEY, nonce)}")
    assert (
        reply.proof == auth.controller_proof(KEY, nonce, reply.nonce, reply.clock_ms) and reply.clock_ms == program.t_ms
    )
    program.t_ms += round_trip_ms
    assert program.handle(f"AUT,{auth.workstation_proof(KEY, nonce, reply.nonce)}")[0].body() == "ACK,AUT,-"
    counter = iter(range(1, 10**6))
    session = auth.session_key(KEY, nonce, reply.nonce)

    def sealed(body: str, t_ms: int | None = None, deliver: bool = True):
        text = auth.seal(session, next(counter), program.t_ms if t_ms is None else t_ms, body)
        return program.handle(text) if deliver else text

    return sealed


def test_it_believes_only_the_workstations_sealed_heartbeat():
    p = _ProgramBySentence()
    sealed = _session(p)
    assert sealed("HBT,500") == []
    assert sealed("MVJ,a.1,160,0,0,0,0,0")[0].body() == "ACK,MVJ,a.1"
    for _ in range(5):  # the workstation is gone: someone else's heartbeats every 0.1 s
        p.t_ms += 100
        (refusal,) = p.handle("HBT,60000")
        assert refusal.code == "AUTH" and refusal.text == "heartbeat: not obeyed: the sentence carries no seal"
    p.t_ms += 150
    (halted,) = p.tick()
    assert halted.code == "DEADMAN" and not p.moving


def test_a_hello_without_the_key_leaves_the_session_in_force():
    p = _ProgramBySentence()
    sealed = _session(p)
    stranger = auth.new_nonce()
    (refused,) = p.handle(f"HEL,{stranger},{'0' * 32}")  # a second writer, without the key
    assert refused.code == "AUTH" and refused.text.startswith(f"hello {stranger}: wrong request")
    assert p.handle("AUT," + "0" * 32)[0].text.startswith("auth: AUT without a HEL first")
    assert sealed("MVJ,a.1,10,0,0,0,0,0")[0].body() == "ACK,MVJ,a.1"


def test_it_refuses_a_move_held_back_and_released_after_the_workstation_died():
    """As the simulator (tests/core/link/test_link_attacks.py): seals carry the time; the program's bound is twice
    the handshake's round trip and half a second, at least 1 s."""
    for held_ms, round_trip_ms, obeyed in (
        (8000, 0, False),
        (20000, 0, False),
        (900, 0, True),
        (3000, 2000, True),
        (5000, 2000, False),
    ):
        p = _ProgramBySentence()
        sealed = _session(p, round_trip_ms)
        assert sealed("HBT,60000") == []
        move = sealed("MVJ,a.1,90,0,0,0,0,0", deliver=False)
        p.t_ms += held_ms
        replies = p.handle(move)
        if obeyed:
            assert replies[0].body() == "ACK,MVJ,a.1", (held_ms, round_trip_ms, replies)
        else:
            assert replies[0].code == "AUTH" and "stale: sealed" in replies[0].text and not p.moving, (held_ms, replies)


def test_its_dead_man_counts_from_when_the_heartbeat_was_sealed():
    p = _ProgramBySentence()
    sealed = _session(p)
    assert sealed("HBT,1000") == []
    assert sealed("MVJ,a.1,160,0,0,0,0,0")[0].body() == "ACK,MVJ,a.1"
    late = sealed("HBT,1000", deliver=False)
    p.t_ms += 800
    assert p.handle(late) == []  # sealed 0.8 s ago: it feeds the dead-man for 0.2 s
    p.t_ms += 250
    (halted,) = p.tick()
    assert halted.code == "DEADMAN" and not p.moving


def test_it_answers_a_flood_of_forged_sentences_at_most_ten_times_a_second_and_a_replayed_hello_never():
    p = _ProgramBySentence()
    sealed = _session(p)
    answered = sum(len(p.handle("HBT,60000")) for _ in range(200))  # 200 within the same millisecond
    assert answered == 10
    p.t_ms += 1000
    assert len(p.handle("HBT,60000")) == 1  # a new second
    nonce = auth.new_nonce()
    hello = f"HEL,{nonce},{auth.hello_request(KEY, nonce)}"
    assert len(p.handle(hello)) == 1 and p.handle(hello) == []
    assert sealed("MVJ,a.1,10,0,0,0,0,0")[0].body() == "ACK,MVJ,a.1"
