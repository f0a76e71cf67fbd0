"""The workstation's side of the link's session authentication (protocol 6, :mod:`calib_core.link.auth`).

The driver calls :meth:`WorkstationAuth.hello` on every (re)connection, hands it the controller's
``HEL``, ``ACK,AUT`` and ``ERR`` replies, and seals motion sentences with :meth:`seal`, each with the time it was
sealed on the controller's clock (read at the handshake). The state says whether the robot may be moved now, and
:attr:`failure` why not.
"""

from __future__ import annotations

import threading
import time
from enum import Enum

from psygnal import Signal

from calib_core.link import auth
from calib_core.link.protocol import Authenticate, ErrorReply, Hello, HelloReply
from calib_core.link.round_trip import RoundTrip

HANDSHAKE_TIMEOUT_S = 1.5
HANDSHAKE_ATTEMPTS = 4
"""An unanswered hello is sent again, each try waiting twice as long as the one before (1.5, 3, 6, 12 s) or
the measured round trip's timeout if that is longer, before the handshake is given up: a controller
simulator starting on a loaded two-core machine once missed the first 1.5 s, and a controller seconds away
(a relay satellite) answers after its round trip. A late answer to an earlier hello is no failure: it times
the round trip, and the newest hello's answer is waited for (the controller answers hellos in order and
keeps only the newest)."""


def handshake_budget_s() -> float:
    """How long every try together waits at least (s): 22.5 s."""
    return HANDSHAKE_TIMEOUT_S * sum(2**k for k in range(HANDSHAKE_ATTEMPTS))


class AuthState(str, Enum):
    """``off``: no key (a protocol-3 controller, nothing sealed); ``pending``: the handshake is under
    way; ``ready``: motion sentences are sealed; ``failed``: no motion (see ``failure``)."""

    OFF = "off"
    PENDING = "pending"
    READY = "ready"
    FAILED = "failed"


class WorkstationAuth:
    """The workstation's side of the link's handshake. ``settled(state, failure)`` when a handshake
    ends (on the link's reader thread).

    Its public members are the handshake's steps as the link's reader calls them (hello, each reply, a lost session, a
    timeout), the sealing of each request, and the state it settled in with why."""

    settled = Signal(object, object)

    def __init__(self, key: bytes | None, key_name: str = "the link key", round_trip: RoundTrip | None = None):
        self._key = key
        self.round_trip = round_trip if round_trip is not None else RoundTrip()
        self._key_name = key_name
        self._changed = threading.Condition()
        self.state = AuthState.OFF if key is None else AuthState.PENDING
        self.failure: str | None = None
        self.sessions = 0
        self.forged_replies = 0
        """Hello replies whose proof held for no hello of ours (another writer's, or forged): ignored."""
        self._nonce: str | None = None
        self._session: bytes | None = None
        self._counter = 0
        self._sent_s = 0.0
        self._attempts = 0
        self._earlier: dict[str, float] = {}  # the nonces of this series' earlier hellos: when each was sent
        self._aut_sent_s: float | None = None
        self._clock_offset_ms = 0.0  # the controller's clock minus this host's monotonic clock, ms

    def _set(self, state: AuthState, failure: str | None = None) -> None:
        with self._changed:
            self.state, self.failure = state, failure
            self._changed.notify_all()
        if state is not AuthState.PENDING:
            self.settled.emit(state, failure)

    def hello(self) -> str | None:
        """The ``HEL`` body that opens a new session (``None`` without a key)."""
        if self._key is None:
            return None
        retry = self.state is AuthState.PENDING and self._nonce is not None
        self._attempts = self._attempts + 1 if retry else 1
        self._earlier = {**self._earlier, self._nonce: self._sent_s} if retry else {}
        self._nonce, self._session, self._counter = auth.new_nonce(), None, 0
        self._sent_s = time.monotonic()
        self._aut_sent_s = None
        self._set(AuthState.PENDING)
        return Hello(self._nonce, auth.hello_request(self._key, self._nonce)).body()

    def on_hello_reply(self, msg: HelloReply) -> str | None:
        """The ``AUT`` body answering the controller's ``HEL`` (``None``: not an answer to this hello). A reply whose
        proof does not hold for this hello is ignored, not a failure: anyone on the line can send one (a controller
        with another key refuses the hello itself, and :meth:`on_error` says so)."""
        if self._key is None or self.state is not AuthState.PENDING or self._nonce is None:
            return None
        now = time.monotonic()
        if not auth.is_nonce(msg.nonce):
            return None
        for nonce, sent_s in self._earlier.items():
            if auth.proof_is_valid(auth.controller_proof(self._key, nonce, msg.nonce, msg.clock_ms), msg.proof):
                # A late answer to an earlier hello: the controller holds the key and is far away; the
                # newest hello is the one it will take an AUT for. Wait for that answer a round trip longer.
                self.round_trip.add(now - sent_s)
                return None
        if not auth.proof_is_valid(auth.controller_proof(self._key, self._nonce, msg.nonce, msg.clock_ms), msg.proof):
            self.forged_replies += 1
            return None
        if not self._earlier:  # Karn's rule: the answer to a hello sent once times the round trip
            self.round_trip.add(now - self._sent_s)
        # the controller read its clock between our hello and this answer: at their midpoint, to within half the trip
        self._clock_offset_ms = msg.clock_ms - 500.0 * (self._sent_s + now)
        self._session = auth.session_key(self._key, self._nonce, msg.nonce)
        self._aut_sent_s = now
        return Authenticate(auth.workstation_proof(self._key, self._nonce, msg.nonce)).body()

    def on_accepted(self) -> None:
        """``ACK,AUT``: the session is open."""
        if self.state is AuthState.PENDING and self._session is not None:
            if self._aut_sent_s is not None:
                self.round_trip.add(time.monotonic() - self._aut_sent_s)
            self.sessions += 1
            self._set(AuthState.READY)

    def on_error(self, msg: ErrorReply) -> bool:
        """An ``ERR`` about the handshake (True: it was one)."""
        if self._key is None:
            return False
        if msg.code == "AUTH" and msg.text.startswith("hello "):
            # the controller refused a hello: ours only if it names our nonce (a flood of others' is not our failure)
            if (
                self.state is AuthState.PENDING
                and self._nonce is not None
                and msg.text.startswith(f"hello {self._nonce}:")
            ):
                self._set(
                    AuthState.FAILED,
                    f"the controller does not hold {self._key_name}: it refused our hello (another key installed?); "
                    "the robot is not moved",
                )
            return True
        if msg.code == "AUTH" and msg.text.startswith("auth:") and self.state is AuthState.PENDING:
            # (in a session, an "auth:" refusal answers another writer's handshake on the line, not ours)
            self._set(AuthState.FAILED, f"the controller refused {self._key_name} ({msg.text}); the robot is not moved")
            return True
        if self.state is AuthState.PENDING and _does_not_know_the_handshake(msg):
            self._set(
                AuthState.FAILED,
                f"the controller does not authenticate as protocol 6 does (it answered {msg.code}: {msg.text}): "
                "videocal moves only a "
                "controller that holds the link key; install the controller program "
                "(resources/controller/videocal_link.pdl, protocol 6) "
                "with `videocal link-key`'s key",
            )
            return True
        return False

    def lost_session(self, msg: ErrorReply) -> bool:
        """A move refused for want of a session (the controller restarted), or for its time (the clocks have drifted
        apart, or the link held it back): time for a new hello, which reads the controller's clock again. The move
        itself is not sent again."""
        return (
            self._key is not None
            and msg.code == "AUTH"
            and (
                "no authenticated session" in msg.text
                or "stale:" in msg.text
                or "ahead of the controller clock" in msg.text
            )
        )

    def _try_wait_s(self) -> float:
        """How long the current try waits for its answer (s): doubling per try, at least the round trip's
        timeout (an AUT already sent waits its own round trip too)."""
        return max(
            HANDSHAKE_TIMEOUT_S * 2 ** (self._attempts - 1),
            2.0 * self.round_trip.rto_s if self._aut_sent_s else self.round_trip.rto_s,
        )

    def check_timeout(self, now_s: float) -> bool:
        """True when an unanswered hello is due to be sent again; after :data:`HANDSHAKE_ATTEMPTS` the
        handshake has failed."""
        if self.state is not AuthState.PENDING or self._nonce is None or now_s - self._sent_s <= self._try_wait_s():
            return False
        if self._attempts < HANDSHAKE_ATTEMPTS:
            return True
        waited = now_s - min([self._sent_s, *self._earlier.values()])
        self._set(
            AuthState.FAILED,
            f"the controller did not answer the handshake ({HANDSHAKE_ATTEMPTS} tries in {waited:.1f} s; a protocol-3 "
            "controller?); the robot is not moved",
        )
        return False

    def wait_settled(self, timeout_s: float) -> AuthState:
        """Wait while the handshake is under way (at most ``timeout_s``); the state then."""
        with self._changed:
            self._changed.wait_for(lambda: self.state is not AuthState.PENDING, timeout_s)
            return self.state

    def seal(self, body: str) -> str:
        """``body`` as sent: sealed in the session (unchanged without a key)."""
        if self._key is None:
            return body
        if self._session is None:
            raise RuntimeError("no session to seal in")
        self._counter += 1
        return auth.seal(self._session, self._counter, self.controller_clock_ms(), body)

    def controller_clock_ms(self, now_s: float | None = None) -> int:
        """Now on the controller's clock (ms), as read at the handshake."""
        return max(0, int(round(1000.0 * (time.monotonic() if now_s is None else now_s) + self._clock_offset_ms)))

    @property
    def why_not(self) -> str:
        if self.state is AuthState.PENDING:
            return "the link's handshake is still under way"
        return self.failure or "the link is not authenticated"


def _does_not_know_the_handshake(msg: ErrorReply) -> bool:
    """Whether ``msg`` is an older controller's answer to our hello: ``UNKNOWN`` about ``HEL`` or ``AUT`` (a
    protocol-5 controller knows no three-field hello, a protocol-3 one no key). Any other error that mentions them
    answers another writer on the line (a flood of old-style two-field hellos draws ``ERR,SYNTAX,HEL with 1 fields``,
    which ours never is) and once made the workstation give up its handshake."""
    if msg.code != "UNKNOWN":
        return False
    text = msg.text
    return text.startswith(("HEL", "AUT")) or "'HEL'" in text or "'AUT'" in text
