"""The protocol fuzzed: any sentence body a line can carry is answered without an exception by the
controller and by the driver, and no body but a correctly sealed one starts a move."""

from __future__ import annotations

import time

from hypothesis import HealthCheck, given, settings, strategies as st

from calib_core.link import auth
from videocal_sim.controller_sim import ControllerLogic
from calib_core.link.driver import ControllerLink
from calib_core.link.protocol import encode

KEY = bytes(range(7, 39))
BODY_CHARS = st.characters(min_codepoint=0x20, max_codepoint=0x7E, blacklist_characters="$*")
KINDS = ["MVJ", "HEL", "AUT", "STP", "HBT", "STR", "RQJ", "VER", "STA", "JNT", "ACK", "DON", "ERR"]
bodies = st.one_of(
    st.text(BODY_CHARS, max_size=300),
    st.builds(lambda k, rest: k + rest, st.sampled_from(KINDS), st.text(BODY_CHARS, max_size=200)),
    st.builds(
        lambda k, fields: ",".join([k, *fields]),
        st.sampled_from(KINDS),
        st.lists(
            st.one_of(
                st.text(BODY_CHARS.filter(lambda c: c != ","), max_size=40),
                st.floats().map(str),
                st.integers().map(str),
                st.from_regex(r"#[0-9]{1,11}:[0-9a-f]{30,34}", fullmatch=True),
                st.from_regex(r"#[0-9]{1,11}:[0-9]{1,11}:[0-9a-f]{30,34}", fullmatch=True),
            ),
            max_size=20,
        ),
    ),
)


def _session(logic: ControllerLogic) -> bytes:
    wn = auth.new_nonce()
    (reply,) = logic.handle(f"HEL,{wn},{auth.hello_request(KEY, wn)}")
    logic.handle(f"AUT,{auth.workstation_proof(KEY, wn, reply.nonce)}")
    return auth.session_key(KEY, wn, reply.nonce)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(bodies, min_size=1, max_size=5))
def test_no_unsealed_body_moves_a_keyed_controller(sequence):
    logic = ControllerLogic(key=KEY)
    _session(logic)
    for body in sequence:
        for reply in logic.handle(body):
            encode(reply.body())  # every reply can be sent
        assert logic.move is None


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 200), st.sampled_from("0123456789abcdef.,-#:x"))
def test_any_altered_character_of_a_sealed_move_is_refused(position, char):
    logic = ControllerLogic(key=KEY)
    session = _session(logic)
    sealed = auth.seal(session, 1, logic.clock_ms(), "MVJ,m1.1,10.0000,-20.0000,30.0000,0.0000,5.5000,-1.0000")
    i = position % len(sealed)
    altered = sealed[:i] + char + sealed[i + 1 :]
    replies = logic.handle(altered)
    moved = logic.move is not None
    assert moved == (altered == sealed), (altered, replies)


@settings(max_examples=400, deadline=None)
@given(bodies)
def test_the_driver_takes_any_body_without_an_exception(body):
    link = ControllerLink("loop://", key=KEY)
    link._dispatch(body, time.monotonic())
    assert link.stats.samples <= 1
