"""The link's session authentication (protocol 6): a handshake on a pre-shared key, and an HMAC and the
sender's time on every motion sentence.

Both ends hold the same 32-byte key (:mod:`calib_core.link.link_key`). A session:

1. workstation: ``$HEL,<wn>,<request>``: ``wn`` 16 hex digits, fresh from ``secrets``; ``request`` the first 32
   hex digits of HMAC-SHA256(key, ``"videocal-request|" wn``): the controller answers only a hello from the key's
   holder (a flood of hellos without it costs the handshake nothing);
2. controller: ``$HEL,<cn>,<proof>,<clock_ms>``: ``cn`` its own fresh nonce, ``clock_ms`` its clock (ms, the clock
   its joint samples are stamped with), ``proof`` = HMAC-SHA256(key, ``"videocal-hello|" wn "|" cn "|" clock_ms``);
3. workstation: ``$AUT,<proof>`` with HMAC-SHA256(key, ``"videocal-auth|" cn "|" wn``); the controller answers
   ``ACK,AUT,-`` or ``ERR,AUTH,...``. The controller times its hello to this answer: the session's round trip.

The session key is HMAC-SHA256(key, ``"videocal-session|" wn "|" cn``). A motion sentence carries a seal as its
last field, ``#<counter>:<t_ms>:<mac>``: ``counter`` 1, 2, 3 ... within the session (a replayed sentence reuses one
and is refused), ``t_ms`` when it was sealed on the controller's clock (the workstation knows that clock from the
handshake, to within half its round trip), ``mac`` the first 32 hex digits of HMAC-SHA256(session key,
``"<counter>|<t_ms>|<body before the seal>"``). The controller refuses a sentence sealed longer ago than
:func:`freshness_bound_ms` of the session's round trip (held back on the way) and keeps the dead-man by the
heartbeats' sealed times, so nothing held back and released later moves the robot. Fresh nonces on both sides make
an old session's sentences worthless in a new one. ``STP`` is never sealed: anyone at the link may stop the robot.
A new ``HEL`` does not end the session in force: only a complete handshake (a right ``AUT``) replaces it.
"""

from __future__ import annotations

import hashlib
import hmac
import re
import secrets
from dataclasses import dataclass

NONCE_HEX = 16
PROOF_HEX = 32
SEALED = frozenset({"MVJ", "HBT"})
"""The sentence types a controller with a key obeys only when sealed: the ones that change what the
robot does (a move; a heartbeat, which keeps a move running and arms or disarms the dead-man)."""

_HEX = re.compile(r"[0-9a-f]+")
_SEAL = re.compile(r"#([0-9]{1,10}):([0-9]{1,10}):([0-9a-f]{32})")

FRESH_MIN_MS = 1000
FRESH_MAX_MS = 15000
FRESH_MARGIN_MS = 500


def freshness_bound_ms(round_trip_ms: float) -> int:
    """How long ago (ms) a sentence may have been sealed and still be obeyed, for a session whose handshake took
    ``round_trip_ms``: twice the round trip and half a second (the workstation's reading of the controller's clock is
    off by up to half a round trip, a sentence takes up to one on its way, and clocks drift), at least 1 s and at most
    15 s (a relay that held the handshake back cannot stretch it further)."""
    return int(min(FRESH_MAX_MS, max(FRESH_MIN_MS, 2.0 * round_trip_ms + FRESH_MARGIN_MS)))


def new_nonce() -> str:
    return secrets.token_hex(NONCE_HEX // 2)


def is_nonce(text: str) -> bool:
    return len(text) == NONCE_HEX and _HEX.fullmatch(text) is not None


def _mac(key: bytes, text: str, n_hex: int = PROOF_HEX) -> str:
    return hmac.new(key, text.encode("ascii"), hashlib.sha256).hexdigest()[:n_hex]


def hello_request(key: bytes, workstation_nonce: str) -> str:
    """What the workstation sends in its ``HEL``: the controller answers only the key's holder."""
    return _mac(key, f"videocal-request|{workstation_nonce}")


def controller_proof(key: bytes, workstation_nonce: str, controller_nonce: str, clock_ms: int) -> str:
    """What the controller sends in its ``HEL``: it knows the key, and this is its clock."""
    return _mac(key, f"videocal-hello|{workstation_nonce}|{controller_nonce}|{clock_ms}")


def workstation_proof(key: bytes, workstation_nonce: str, controller_nonce: str) -> str:
    """What the workstation sends in ``AUT``: it knows the key."""
    return _mac(key, f"videocal-auth|{controller_nonce}|{workstation_nonce}")


def session_key(key: bytes, workstation_nonce: str, controller_nonce: str) -> bytes:
    """The session's sealing key (32 bytes)."""
    return hmac.new(
        key, f"videocal-session|{workstation_nonce}|{controller_nonce}".encode("ascii"), hashlib.sha256
    ).digest()


def seal(session: bytes, counter: int, t_ms: int, body: str) -> str:
    """``body`` with its seal appended: ``<body>,#<counter>:<t_ms>:<mac>`` (``t_ms``: now on the controller's clock)."""
    return f"{body},#{counter}:{t_ms}:{_mac(session, f'{counter}|{t_ms}|{body}')}"


@dataclass(frozen=True)
class Seal:
    counter: int
    t_ms: int
    mac: str


def split_seal(body: str) -> tuple[str, Seal | None]:
    """``(body without its seal, seal)``; ``(body, None)`` when the last field is no seal."""
    inner, comma, last = body.rpartition(",")
    match = _SEAL.fullmatch(last) if comma else None
    if match is None:
        return body, None
    return inner, Seal(int(match.group(1)), int(match.group(2)), match.group(3))


def seal_is_valid(session: bytes, inner: str, s: Seal) -> bool:
    return hmac.compare_digest(_mac(session, f"{s.counter}|{s.t_ms}|{inner}"), s.mac)


def staleness(s: Seal, now_ms: int, bound_ms: int) -> str | None:
    """Why a sentence sealed at ``s.t_ms`` is not to be obeyed at ``now_ms`` (both on the controller's clock, ms)
    under the session's ``bound_ms``; ``None`` when it is fresh."""
    age = now_ms - s.t_ms
    if age > bound_ms:
        return f"stale: sealed {age} ms ago (more than the {bound_ms} ms this session allows: held back on the way?)"
    if -age > bound_ms:
        return f"sealed {-age} ms ahead of the controller clock (more than {bound_ms} ms): the clocks disagree"
    return None


def proof_is_valid(expected: str, given: str) -> bool:
    return hmac.compare_digest(expected.encode("ascii", "replace"), given.encode("ascii", "replace"))
