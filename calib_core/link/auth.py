"""The link's session authentication (protocol 4): a handshake on a pre-shared key and an HMAC
on every motion sentence.

Both ends hold the same 32-byte key (:mod:`calib_core.link.link_key`). A session:

1. workstation: ``$HEL,<wn>``: ``wn`` 16 hex digits, fresh from ``secrets``;
2. controller: ``$HEL,<cn>,<proof>``: ``cn`` its own fresh nonce, ``proof`` = the first 32 hex digits of
   HMAC-SHA256(key, ``"videocal-hello|" wn "|" cn``) (the controller holds the key);
3. workstation: ``$AUT,<proof>`` with HMAC-SHA256(key, ``"videocal-auth|" cn "|" wn``) (so does the
   workstation); the controller answers ``ACK,AUT,-`` or ``ERR,AUTH,...``.

The session key is HMAC-SHA256(key, ``"videocal-session|" wn "|" cn``). A motion sentence carries a
seal as its last field, ``#<counter>:<mac>``: ``counter`` 1, 2, 3 ... within the session (a replayed
sentence reuses one and is refused), ``mac`` the first 32 hex digits of HMAC-SHA256(session key,
``"<counter>|<body before the seal>"``). Fresh nonces on both sides make an old session's sentences
worthless in a new one. ``STP`` is never sealed: anyone at the link may stop the robot. A new
``HEL`` does not end the session in force: only a complete handshake (a right ``AUT``) replaces it,
so a process without the key cannot end the workstation's session.
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
_SEAL = re.compile(r"#([0-9]{1,10}):([0-9a-f]{32})")


def new_nonce() -> str:
    return secrets.token_hex(NONCE_HEX // 2)


def is_nonce(text: str) -> bool:
    return len(text) == NONCE_HEX and _HEX.fullmatch(text) is not None


def _mac(key: bytes, text: str, n_hex: int = PROOF_HEX) -> str:
    return hmac.new(key, text.encode("ascii"), hashlib.sha256).hexdigest()[:n_hex]


def controller_proof(key: bytes, workstation_nonce: str, controller_nonce: str) -> str:
    """What the controller sends in its ``HEL``: it knows the key."""
    return _mac(key, f"videocal-hello|{workstation_nonce}|{controller_nonce}")


def workstation_proof(key: bytes, workstation_nonce: str, controller_nonce: str) -> str:
    """What the workstation sends in ``AUT``: it knows the key."""
    return _mac(key, f"videocal-auth|{controller_nonce}|{workstation_nonce}")


def session_key(key: bytes, workstation_nonce: str, controller_nonce: str) -> bytes:
    """The session's sealing key (32 bytes)."""
    return hmac.new(key, f"videocal-session|{workstation_nonce}|{controller_nonce}".encode("ascii"), hashlib.sha256).digest()


def seal(session: bytes, counter: int, body: str) -> str:
    """``body`` with its seal appended: ``<body>,#<counter>:<mac>``."""
    return f"{body},#{counter}:{_mac(session, f'{counter}|{body}')}"


@dataclass(frozen=True)
class Seal:
    counter: int
    mac: str


def split_seal(body: str) -> tuple[str, Seal | None]:
    """``(body without its seal, seal)``; ``(body, None)`` when the last field is no seal."""
    inner, comma, last = body.rpartition(",")
    match = _SEAL.fullmatch(last) if comma else None
    if match is None:
        return body, None
    return inner, Seal(int(match.group(1)), match.group(2))


def seal_is_valid(session: bytes, inner: str, s: Seal) -> bool:
    return hmac.compare_digest(_mac(session, f"{s.counter}|{inner}"), s.mac)


def proof_is_valid(expected: str, given: str) -> bool:
    return hmac.compare_digest(expected.encode("ascii", "replace"), given.encode("ascii", "replace"))
