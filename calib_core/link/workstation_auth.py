"""The workstation's side of the link's session authentication (protocol 4, :mod:`calib_core.link.auth`).

The driver calls :meth:`WorkstationAuth.hello` on every (re)connection, hands it the controller's
``HEL``, ``ACK,AUT`` and ``ERR`` replies, and seals motion sentences with :meth:`seal`. The state says
whether the robot may be moved now, and :attr:`failure` why not.
"""

from __future__ import annotations

import threading
import time
from enum import Enum

from psygnal import Signal

from calib_core.link import auth
from calib_core.link.protocol import Authenticate, ErrorReply, Hello, HelloReply

HANDSHAKE_TIMEOUT_S = 1.5
HANDSHAKE_ATTEMPTS = 3
"""An unanswered hello is sent again (after 1.5 s, then 3 s more) before the handshake is given up: a
controller simulator starting on a loaded two-core machine once missed the first 1.5 s."""


class AuthState(str, Enum):
    """``off``: no key (a protocol-3 controller, nothing sealed); ``pending``: the handshake is under
    way; ``ready``: motion sentences are sealed; ``failed``: no motion (see ``failure``)."""

    OFF = "off"
    PENDING = "pending"
    READY = "ready"
    FAILED = "failed"


class WorkstationAuth:
    """The workstation's side of the link's handshake. ``settled(state, failure)`` when a handshake
    ends (on the link's reader thread)."""

    settled = Signal(object, object)

    def __init__(self, key: bytes | None, key_name: str = "the link key"):
        self._key = key
        self._key_name = key_name
        self._changed = threading.Condition()
        self.state = AuthState.OFF if key is None else AuthState.PENDING
        self.failure: str | None = None
        self.sessions = 0
        self._nonce: str | None = None
        self._session: bytes | None = None
        self._counter = 0
        self._sent_s = 0.0
        self._attempts = 0

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
        self._nonce, self._session, self._counter = auth.new_nonce(), None, 0
        self._sent_s = time.monotonic()
        self._set(AuthState.PENDING)
        return Hello(self._nonce).body()

    def on_hello_reply(self, msg: HelloReply) -> str | None:
        """The ``AUT`` body answering the controller's ``HEL`` (``None``: the controller is not to be trusted)."""
        if self._key is None or self.state is not AuthState.PENDING or self._nonce is None:
            return None
        if not auth.is_nonce(msg.nonce) or not auth.proof_is_valid(auth.controller_proof(self._key, self._nonce, msg.nonce), msg.proof):
            self._set(AuthState.FAILED, f"the controller does not hold {self._key_name}: its proof is wrong (another key installed?); the robot is not moved")
            return None
        self._session = auth.session_key(self._key, self._nonce, msg.nonce)
        return Authenticate(auth.workstation_proof(self._key, self._nonce, msg.nonce)).body()

    def on_accepted(self) -> None:
        """``ACK,AUT``: the session is open."""
        if self.state is AuthState.PENDING and self._session is not None:
            self.sessions += 1
            self._set(AuthState.READY)

    def on_error(self, msg: ErrorReply) -> bool:
        """An ``ERR`` about the handshake (True: it was one)."""
        if self._key is None:
            return False
        if msg.code == "AUTH" and msg.text.startswith("auth:") and self.state is AuthState.PENDING:
            # (in a session, an "auth:" refusal answers another writer's handshake on the line, not ours)
            self._set(AuthState.FAILED, f"the controller refused {self._key_name} ({msg.text}); the robot is not moved")
            return True
        if self.state is AuthState.PENDING and not msg.text.startswith("move ") and ("HEL" in msg.text or "AUT" in msg.text):
            self._set(AuthState.FAILED, f"the controller does not authenticate (it answered {msg.code}: {msg.text}): videocal moves only a controller that "
                                        "holds the link key; install the controller program (resources/controller/videocal_link.pdl) with `videocal link-key`'s key")
            return True
        return False

    def lost_session(self, msg: ErrorReply) -> bool:
        """A move refused for want of a session (the controller restarted): time for a new hello."""
        return self._key is not None and msg.code == "AUTH" and "no authenticated session" in msg.text

    def check_timeout(self, now_s: float) -> bool:
        """True when an unanswered hello is due to be sent again; after :data:`HANDSHAKE_ATTEMPTS` the
        handshake has failed."""
        if self.state is not AuthState.PENDING or self._nonce is None or now_s - self._sent_s <= HANDSHAKE_TIMEOUT_S * self._attempts:
            return False
        if self._attempts < HANDSHAKE_ATTEMPTS:
            return True
        waited = HANDSHAKE_TIMEOUT_S * sum(range(1, HANDSHAKE_ATTEMPTS + 1))
        self._set(AuthState.FAILED, f"the controller did not answer the handshake ({HANDSHAKE_ATTEMPTS} tries in {waited:g} s; a protocol-3 controller?); the robot is not moved")
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
        return auth.seal(self._session, self._counter, body)

    @property
    def why_not(self) -> str:
        if self.state is AuthState.PENDING:
            return "the link's handshake is still under way"
        return self.failure or "the link is not authenticated"
