"""The session handshake on the pre-shared key and the seal on motion sentences (protocol 6: the hello proves the
key, the controller's answer carries its clock, seals carry the time they were made), at the controller's logic,
through the real simulator process, and the key file itself."""

from __future__ import annotations

import hashlib
import os
import stat
import threading
import time

import pytest

from calib_core.link import auth
from videocal_sim.controller_sim import ControllerLogic
from calib_core.link.driver import ControllerLink
from calib_core.link.link_key import LinkKeyError, default_key_path, read_key, user_key, write_new_key
from calib_core.connectors.link_types import MoveError
from calib_core.link.protocol import Ack, HelloReply, encode
from calib_core.link.workstation_auth import AuthState, WorkstationAuth

from tests.core.link.raw_link import first_error_reply
from tests.core.link.sim_process import SimProcess

KEY = bytes(range(32))


def _hmac_by_hand(key: bytes, text: str) -> str:
    """RFC 2104 written out (ipad/opad), to check the module's HMAC a second way."""
    block = key.ljust(64, b"\0")
    inner = hashlib.sha256(bytes(b ^ 0x36 for b in block) + text.encode()).digest()
    return hashlib.sha256(bytes(b ^ 0x5C for b in block) + inner).hexdigest()


def test_proofs_and_seals_are_rfc2104_hmacs_of_the_documented_texts():
    wn, cn = "0123456789abcdef", "fedcba9876543210"
    assert auth.hello_request(KEY, wn) == _hmac_by_hand(KEY, f"videocal-request|{wn}")[:32]
    assert auth.controller_proof(KEY, wn, cn, 123456) == _hmac_by_hand(KEY, f"videocal-hello|{wn}|{cn}|123456")[:32]
    assert auth.workstation_proof(KEY, wn, cn) == _hmac_by_hand(KEY, f"videocal-auth|{cn}|{wn}")[:32]
    session = auth.session_key(KEY, wn, cn)
    assert session.hex() == _hmac_by_hand(KEY, f"videocal-session|{wn}|{cn}")
    body = "MVJ,mab12.1,10.0000,0.0000,-5.2500"
    sealed = auth.seal(session, 7, 98765, body)
    assert sealed == f"{body},#7:98765:{_hmac_by_hand(session, f'7|98765|{body}')[:32]}"
    inner, s = auth.split_seal(sealed)
    assert inner == body and s.counter == 7 and s.t_ms == 98765 and auth.seal_is_valid(session, inner, s)
    assert not auth.seal_is_valid(session, body.replace("10.0000", "90.0000"), s)
    assert not auth.seal_is_valid(session, inner, auth.Seal(7, 98766, s.mac))  # the time is sealed too
    assert auth.split_seal(body) == (body, None)
    assert (
        len(
            encode(
                auth.seal(session, 4_000_000_000, 9_999_999_999, "MVJ,mffff.99999," + ",".join(["-999999.9999"] * 16))
            )
        )
        <= 320
    )


@pytest.mark.parametrize("round_trip_ms, bound_ms", [(0, 1000), (10, 1000), (400, 1300), (3700, 7900), (9000, 15000)])
def test_the_freshness_bound_follows_the_handshake_s_round_trip(round_trip_ms, bound_ms):
    assert auth.freshness_bound_ms(round_trip_ms) == bound_ms


def _handshake(logic: ControllerLogic, key: bytes = KEY) -> bytes | None:
    """A session opened by the holder of ``key`` (None when the controller refuses its hello: another key)."""
    wn = auth.new_nonce()
    before_ms = logic.clock_ms()
    (reply,) = logic.handle(f"HEL,{wn},{auth.hello_request(key, wn)}")
    after_ms = logic.clock_ms()
    if key != KEY:
        assert reply.code == "AUTH" and reply.text.startswith(f"hello {wn}: wrong request")
        return None
    assert isinstance(reply, HelloReply) and reply.proof == auth.controller_proof(KEY, wn, reply.nonce, reply.clock_ms)
    assert before_ms <= reply.clock_ms <= after_ms  # the controller's clock when it answered (a loaded machine is slow)
    (ack,) = logic.handle(f"AUT,{auth.workstation_proof(key, wn, reply.nonce)}")
    assert ack == Ack("AUT", "-")
    return auth.session_key(key, wn, reply.nonce)


def _sealed(logic: ControllerLogic, session: bytes, counter: int, body: str) -> str:
    return auth.seal(session, counter, logic.clock_ms(), body)


def _moved(replies) -> bool:
    return any(isinstance(r, Ack) and r.cmd == "MVJ" for r in replies)


def test_a_keyed_controller_obeys_only_sealed_moves_of_its_session():
    logic = ControllerLogic(key=KEY)
    move = "MVJ,m1.1,10,0,0,0,0,0"
    (refused,) = logic.handle(move)
    assert refused.code == "AUTH" and "no authenticated session" in refused.text and logic.move is None
    session = _handshake(logic)
    (refused,) = logic.handle(move)  # a session, but the sentence is not sealed
    assert refused.code == "AUTH" and "no seal" in refused.text
    sealed = _sealed(logic, session, 1, move)
    assert _moved(logic.handle(sealed))
    logic.handle("STP")
    assert logic.handle(sealed)[0].code == "AUTH"  # replayed: same counter
    tampered = sealed.replace("MVJ,m1.1,10,", "MVJ,m1.1,90,")
    assert "wrong seal" in logic.handle(tampered)[0].text
    assert _moved(logic.handle(_sealed(logic, session, 5, "MVJ,m1.2,20,0,0,0,0,0")))  # counters may skip, never go back
    _handshake(logic)  # a new session: the old one's seals are worthless
    assert "wrong seal" in logic.handle(_sealed(logic, session, 9, "MVJ,m1.3,0,0,0,0,0,0"))[0].text
    assert len(logic.auth_refusals) == 5


def test_stop_needs_no_session_and_a_wrong_key_gets_none():
    logic = ControllerLogic(key=KEY)
    session = _handshake(logic)
    assert _moved(logic.handle(_sealed(logic, session, 1, "MVJ,m1.1,150,0,0,0,0,0")))
    logic.end_session()  # the workstation went away
    stop = logic.handle("STP")
    assert stop[0].code == "STOPPED" and stop[-1] == Ack("STP", "-") and logic.move is None
    assert _handshake(logic, key=bytes(32)) is None and logic.auth_refusals[-1].startswith("hello ")
    guessed = auth.session_key(bytes(32), auth.new_nonce(), auth.new_nonce())
    assert logic.handle(_sealed(logic, guessed, 1, "MVJ,m1.2,1,0,0,0,0,0"))[0].code == "AUTH"
    (refused,) = logic.handle("AUT," + "0" * 32)
    assert refused.code == "AUTH" and "without a HEL" in refused.text


def test_a_protocol_3_controller_answers_hello_as_unknown():
    logic = ControllerLogic()
    wn = auth.new_nonce()
    (reply,) = logic.handle(f"HEL,{wn},{auth.hello_request(KEY, wn)}")
    assert reply.code == "UNKNOWN" and "HEL" in reply.text
    assert _moved(logic.handle("MVJ,m1.1,1,0,0,0,0,0"))


@pytest.fixture
def sim(tmp_path):
    procs = []

    def start(*args):
        p = SimProcess(*args, link=tmp_path / f"controller{len(procs)}")
        procs.append(p)
        return p

    yield start
    for p in procs:
        p.stop()


def test_the_simulator_refuses_and_logs_a_raw_unauthenticated_move(sim):
    s = sim("--pty")
    err = first_error_reply(s.url, "MVJ,x1,10,0,0,0,0,0")
    assert err.code == "AUTH" and err.text.startswith("move x1: not obeyed")
    s.proc.terminate()
    assert "refused: move x1: not obeyed: no authenticated session" in s.proc.stderr.read()


def test_the_driver_moves_only_with_the_controllers_key(sim, tmp_path):
    s = sim("--pty")
    with ControllerLink(s.url, rate_hz=50).start(wait_open=True) as link:
        assert link.auth_state is AuthState.READY
        link.move_joints((5.0, 0, 0, 0, 0, 0), timeout_s=10).wait(10)
    other = tmp_path / "other.key"
    with ControllerLink(s.url, rate_hz=50, key=write_new_key(other)).start(wait_open=True) as intruder:
        assert intruder.auth_state is AuthState.FAILED and "does not hold" in intruder.auth_failure
        handle = intruder.move_joints((40.0, 0, 0, 0, 0, 0))
        assert not handle.sent
        with pytest.raises(MoveError, match="not sent: the controller does not hold"):
            handle.wait(1)
        assert intruder.wait_for_samples(intruder.stats.samples + 5, 2)
        assert intruder.latest.joints_deg[0] == pytest.approx(5.0, abs=1e-3)  # it did not move


def test_a_controller_without_authentication_is_not_moved(sim):
    s = sim("--pty", "--open")
    with ControllerLink(s.url, rate_hz=50).start(wait_open=True) as link:
        assert link.auth_state is AuthState.FAILED and "does not authenticate" in link.auth_failure
        assert not link.move_joints((40.0, 0, 0, 0, 0, 0)).sent
    with ControllerLink(s.url, rate_hz=50, key=None).start(wait_open=True) as old_style:  # the caller's explicit choice
        old_style.move_joints((1.0, 0, 0, 0, 0, 0), timeout_s=10).wait(10)


def test_a_rebooted_controller_gets_a_new_session_and_obeys_again(sim):
    s = sim("--pty", "--reboot-after", "0.8", "--reboot-downtime", "0.3")
    with ControllerLink(s.url, rate_hz=100).start(wait_open=True) as link:
        assert link.auth_state is AuthState.READY
        s.next_announcement()  # the reboot's new pty
        deadline = time.monotonic() + 5
        while link._auth.sessions < 2 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert link._auth.sessions == 2 and link.auth_state is AuthState.READY
        link.move_joints((3.0, 0, 0, 0, 0, 0), timeout_s=10).wait(10)


def test_the_key_file_is_private_and_made_once(tmp_path):
    path = tmp_path / "link.key"
    keys = []
    threads = [threading.Thread(target=lambda: keys.append(write_new_key(path))) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(set(keys)) == 1 and read_key(path) == keys[0]
    assert stat.S_IMODE(path.stat().st_mode) == 0o600 and [p.name for p in tmp_path.iterdir()] == ["link.key"]
    os.chmod(path, 0o644)
    with pytest.raises(LinkKeyError, match=r"readable by others .*chmod 600"):
        read_key(path)
    path.write_text("not hex\n")
    os.chmod(path, 0o600)
    with pytest.raises(LinkKeyError, match="not hex digits"):
        read_key(path)
    with pytest.raises(LinkKeyError, match="no link key there"):
        read_key(tmp_path / "missing.key")
    assert write_new_key(path, replace=True) != keys[0]


def test_the_user_key_lives_in_the_config_folder():
    assert str(default_key_path()).startswith(os.environ["XDG_CONFIG_HOME"])
    assert user_key() == read_key(default_key_path())


def test_an_unanswered_hello_is_sent_again_before_the_handshake_fails():
    """A controller simulator starting on a loaded machine once missed the only 1.5 s the driver gave it:
    each try waits twice as long as the one before (1.5, 3, 6, 12 s) before the handshake fails."""
    ws = WorkstationAuth(KEY)
    first = ws.hello()
    t0 = ws._sent_s
    assert not ws.check_timeout(t0 + 1.4) and ws.check_timeout(t0 + 1.6)
    second = ws.hello()
    assert second != first and ws.state is AuthState.PENDING
    for wait in (3.0, 6.0):
        t = ws._sent_s
        assert not ws.check_timeout(t + wait - 0.1) and ws.check_timeout(t + wait + 0.1)
        ws.hello()
    t3 = ws._sent_s
    assert not ws.check_timeout(t3 + 11.9) and ws.state is AuthState.PENDING
    assert not ws.check_timeout(t3 + 12.1) and ws.state is AuthState.FAILED and "4 tries in" in ws.failure
    # the reply to the latest hello is what counts; a late reply to the failed one is not believed
    nonce = ws._nonce
    reply = HelloReply("0123456789abcdef", auth.controller_proof(KEY, nonce, "0123456789abcdef", 5), 5)
    assert ws.on_hello_reply(reply) is None


def test_a_late_answer_to_an_earlier_hello_times_the_round_trip_and_the_newest_one_opens_the_session():
    """A controller a few seconds away: its answer to the first hello arrives after the second was sent.
    That answer is no wrong key: it measures the round trip (the next try then waits at least that
    long), and the answer to the newest hello, the one the controller keeps, opens the session."""
    controller = ControllerLogic(key=KEY)
    ws = WorkstationAuth(KEY)
    to_controller = [ws.hello()]
    ws._sent_s -= 3.0  # the first hello went out 3 s ago ...
    assert ws.check_timeout(time.monotonic())  # ... and its try (1.5 s) is over: sent again
    to_controller.append(ws.hello())
    replies = [r for body in to_controller for r in controller.handle(body)]  # in order, as TCP delivers
    assert all(isinstance(r, HelloReply) for r in replies) and len(replies) == 2
    assert ws.on_hello_reply(replies[0]) is None and ws.state is AuthState.PENDING  # late: not a failure
    assert ws.round_trip.samples == 1 and ws.round_trip.last_s >= 3.0
    assert ws._try_wait_s() >= ws.round_trip.rto_s >= 3.0  # the newest try now waits a round trip at least
    aut = ws.on_hello_reply(replies[1])
    assert aut is not None
    answer = controller.handle(aut)
    assert answer == [Ack("AUT", "-")]
    ws.on_accepted()
    assert ws.state is AuthState.READY


def test_a_controller_with_another_key_refuses_our_hello_and_we_say_so():
    controller = ControllerLogic(key=bytes(32))
    ws = WorkstationAuth(KEY)
    first = ws.hello()
    ws._sent_s -= 2.0
    assert ws.check_timeout(time.monotonic())
    second = ws.hello()
    # its refusal of the earlier hello is not about the newest one; of the newest, it is
    assert ws.on_error(controller.handle(first)[0]) and ws.state is AuthState.PENDING
    assert (
        ws.on_error(controller.handle(second)[0]) and ws.state is AuthState.FAILED and "refused our hello" in ws.failure
    )


def test_forged_hello_replies_and_refusals_of_others_hellos_do_not_fail_the_handshake():
    """Anyone on the line can send a HEL reply or an ERR,AUTH naming a hello: neither ends ours. The answer to
    our own hello, proven with the key, opens the session."""
    controller = ControllerLogic(key=KEY)
    ws = WorkstationAuth(KEY)
    ours = ws.hello()
    assert ws.on_hello_reply(HelloReply("0123456789abcdef", "0" * 32, 1000)) is None and ws.forged_replies == 1
    stranger = auth.new_nonce()
    assert ws.on_error(controller.handle(f"HEL,{stranger},{'1' * 32}")[0]) and ws.state is AuthState.PENDING
    (reply,) = controller.handle(ours)
    aut = ws.on_hello_reply(reply)
    assert controller.handle(aut) == [Ack("AUT", "-")]
    ws.on_accepted()
    assert ws.state is AuthState.READY
