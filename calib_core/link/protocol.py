"""The wire protocol: NMEA-0183-style ASCII sentences and their typed messages.

A sentence is ``$`` + body + ``*`` + two upper-case hex digits (the XOR of every body byte)
+ CR LF, at most 320 bytes. Fields are separated by commas; angles are degrees with up to
4 decimals. The full description is in ``docs/controller-protocol.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from calib_core.connectors.link_types import JointSample as SharedJointSample

PROTOCOL_VERSION = 6
# Version 2 carries any number of joints (1 to MAX_JOINTS) and so allows longer sentences; version 4
# adds a seal to motion sentences, 56 bytes with version 6's time (16 joints of 1e6 still fit).
MAX_SENTENCE_BYTES = 320
MAX_JOINTS = 16
SEQ_MODULUS = 2**32


class ProtocolError(ValueError):
    """A sentence body that is not a valid message. ``kind``: ``malformed``, ``non_finite`` (or
    beyond any robot's: a joint at 1e308 deg) or ``unknown``."""

    def __init__(self, kind: str, message: str):
        self.kind = kind
        super().__init__(message)


def checksum(body: bytes) -> int:
    """XOR of every byte of the body (between ``$`` and ``*``)."""
    c = 0
    for b in body:
        c ^= b
    return c


def encode(body: str) -> bytes:
    """The full sentence for ``body``; ``ValueError`` if it cannot be sent as one."""
    raw = body.encode("ascii")
    if any(ch in raw for ch in b"$*\r\n"):
        raise ValueError(f"a sentence body may not contain $, *, CR or LF: {body!r}")
    sentence = b"$" + raw + b"*" + f"{checksum(raw):02X}".encode() + b"\r\n"
    if len(sentence) > MAX_SENTENCE_BYTES:
        raise ValueError(f"sentence of {len(sentence)} bytes exceeds {MAX_SENTENCE_BYTES}: {body!r}")
    return sentence


def format_angle(deg: float) -> str:
    return f"{deg:.4f}"


# --- messages from the controller ------------------------------------------------------------
@dataclass(frozen=True)
class JointSample(SharedJointSample):
    """``$JNT,<seq>,<t_ms>,<q1>,...,<qn>``: a joint sample on the wire (the connectors' shared
    :class:`~calib_core.connectors.link_types.JointSample`). ``seq`` wraps at 2^32."""

    def body(self) -> str:
        return ",".join(
            ["JNT", str(self.seq % SEQ_MODULUS), str(self.t_ms)] + [format_angle(q) for q in self.joints_deg]
        )


@dataclass(frozen=True)
class Ack:
    """``$ACK,<cmd>,<id>``: a command was accepted (``id`` is the move id, ``-`` for others)."""

    cmd: str
    id: str

    def body(self) -> str:
        return f"ACK,{self.cmd},{self.id}"


@dataclass(frozen=True)
class Done:
    """``$DON,<id>``: the move ``id`` finished."""

    id: str

    def body(self) -> str:
        return f"DON,{self.id}"


@dataclass(frozen=True)
class StateReport:
    """``$STA,<state>,<text>``: the controller's state (``IDLE``, ``MOVING``, ``FAULT``) and a remark."""

    state: str
    text: str

    def body(self) -> str:
        return f"STA,{self.state},{self.text}"


@dataclass(frozen=True)
class ErrorReply:
    """``$ERR,<code>,<text>``: a command was refused or failed."""

    code: str
    text: str

    def body(self) -> str:
        # A refusal quotes what it refuses (a move id, a number): cut so the sentence always fits the
        # protocol's limit, whatever it quotes.
        head = f"ERR,{self.code},"
        room = MAX_SENTENCE_BYTES - len("$*HH\r\n") - len(head)
        return head + (self.text if len(self.text) <= room else self.text[: room - 3] + "...")


# --- commands to the controller --------------------------------------------------------------
@dataclass(frozen=True)
class RequestJoints:
    """``$RQJ``: send one joint sample now (the paper's cyclic request)."""

    def body(self) -> str:
        return "RQJ"


@dataclass(frozen=True)
class Stream:
    """``$STR,<hz>``: stream joint samples at ``hz`` (0 stops)."""

    hz: float

    def body(self) -> str:
        return f"STR,{self.hz:g}"


@dataclass(frozen=True)
class MoveJoints:
    """``$MVJ,<id>,<q1>,...,<qn>``: move to these joints (deg or mm, the controller's axis order)."""

    id: str
    joints_deg: tuple[float, ...]

    def body(self) -> str:
        return ",".join(["MVJ", self.id] + [format_angle(q) for q in self.joints_deg])


@dataclass(frozen=True)
class Stop:
    """``$STP``: stop now. The controller brings the robot to rest where it is and ends the move
    that was running with ``ERR,STOPPED,move <id>: ...``; it answers ``ACK,STP,-``."""

    def body(self) -> str:
        return "STP"


@dataclass(frozen=True)
class Heartbeat:
    """``$HBT,<timeout_ms>``: the workstation is alive. Once one has arrived, the controller stops a
    running move (``ERR,DEADMAN,move <id>: ...``) when no heartbeat follows within ``timeout_ms``;
    ``0`` disarms the dead-man. No reply."""

    timeout_ms: int

    def body(self) -> str:
        return f"HBT,{self.timeout_ms}"


@dataclass(frozen=True)
class Hello:
    """``$HEL,<nonce>,<request>``: the workstation opens an authenticated session; ``request`` proves it holds the
    key (protocol 6; :func:`calib_core.link.auth.hello_request`)."""

    nonce: str
    request: str

    def body(self) -> str:
        return f"HEL,{self.nonce},{self.request}"


@dataclass(frozen=True)
class HelloReply:
    """``$HEL,<nonce>,<proof>,<clock_ms>``: the controller's nonce, its clock (ms) and its proof that it holds the
    key (protocol 6)."""

    nonce: str
    proof: str
    clock_ms: int

    def body(self) -> str:
        return f"HEL,{self.nonce},{self.proof},{self.clock_ms}"


@dataclass(frozen=True)
class Authenticate:
    """``$AUT,<proof>``: the workstation's proof that it holds the key; answered ``ACK,AUT,-``."""

    proof: str

    def body(self) -> str:
        return f"AUT,{self.proof}"


@dataclass(frozen=True)
class RequestVersion:
    """``$VER``: which protocol version the controller speaks and how many joints it drives."""

    def body(self) -> str:
        return "VER"


@dataclass(frozen=True)
class VersionReport:
    """``$VER,<version>,<n_joints>``: the controller's answer to ``$VER``."""

    version: int
    n_joints: int

    def body(self) -> str:
        return f"VER,{self.version},{self.n_joints}"


@dataclass(frozen=True)
class RequestState:
    """``$STA``: report the controller state."""

    def body(self) -> str:
        return "STA"


Message = (
    JointSample
    | Ack
    | Done
    | StateReport
    | ErrorReply
    | VersionReport
    | RequestJoints
    | Stream
    | MoveJoints
    | RequestState
    | RequestVersion
    | Stop
    | Heartbeat
    | Hello
    | HelloReply
    | Authenticate
)


def _number(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ProtocolError("malformed", f"{what}: not a number: {text!r}") from None
    if not math.isfinite(value):
        raise ProtocolError("non_finite", f"{what}: not finite: {text!r}")
    return value


MAX_JOINT_VALUE = 1e6
"""The largest joint value (deg or mm) a sample may carry: a joint at 1e308 deg is no robot's, and was printed and
plotted as one. (A move's target beyond it parses, and the controller refuses it as beyond its limits: LIMIT.)"""


def _joint(text: str, what: str) -> float:
    value = _number(text, what)
    if abs(value) > MAX_JOINT_VALUE:
        raise ProtocolError("non_finite", f"{what}: {text} is no joint's value (beyond {MAX_JOINT_VALUE:g} deg or mm)")
    return value


def _integer(text: str, what: str) -> int:
    if not text.isdigit():
        raise ProtocolError("malformed", f"{what}: not a non-negative integer: {text!r}")
    return int(text)


MAX_ID_CHARS = 32
"""A move id's longest (the controller program keeps it in a ``STRING[32]``)."""


def _token(text: str, what: str) -> str:
    if len(text) > MAX_ID_CHARS:
        raise ProtocolError("malformed", f"{what}: longer than {MAX_ID_CHARS} characters ({len(text)})")
    if not text or not all(c.isalnum() or c in "_-." for c in text):
        raise ProtocolError("malformed", f"{what}: not a valid identifier: {text!r}")
    return text


def _hex(text: str, what: str) -> str:
    if not 1 <= len(text) <= 64 or any(c not in "0123456789abcdef" for c in text):
        raise ProtocolError("malformed", f"{what}: not 1 to 64 lower-case hex digits: {text!r}")
    return text


def _clock_ms(text: str) -> int:
    if not 1 <= len(text) <= 10 or not text.isdigit():
        raise ProtocolError("malformed", f"HEL clock: not 1 to 10 decimal digits: {text!r}")
    return int(text)


def parse_body(body: str) -> Message:
    """The message of a sentence body (checksum already verified); :class:`ProtocolError` if invalid."""
    fields = body.split(",")
    kind = fields[0]
    n = len(fields)
    if kind == "JNT":
        if not 4 <= n <= 3 + MAX_JOINTS:
            raise ProtocolError(
                "malformed", f"JNT needs a sequence number, a time and 1 to {MAX_JOINTS} joint values; got {n} fields"
            )
        seq = _integer(fields[1], "JNT seq")
        if seq >= SEQ_MODULUS:
            raise ProtocolError("malformed", f"JNT seq {seq} exceeds 2^32 - 1")
        return JointSample(
            seq, _integer(fields[2], "JNT t_ms"), tuple(_joint(f, f"JNT q{i + 1}") for i, f in enumerate(fields[3:]))
        )
    if kind == "ACK" and n == 3:
        return Ack(_token(fields[1], "ACK cmd"), _token(fields[2], "ACK id"))
    if kind == "DON" and n == 2:
        return Done(_token(fields[1], "DON id"))
    if kind == "STA" and n == 1:
        return RequestState()
    if kind == "STA" and n == 3:
        return StateReport(_token(fields[1], "STA state"), fields[2])
    if kind == "ERR" and n == 3:
        return ErrorReply(_token(fields[1], "ERR code"), fields[2])
    if kind == "VER" and n == 1:
        return RequestVersion()
    if kind == "VER" and n == 3:
        return VersionReport(_integer(fields[1], "VER version"), _integer(fields[2], "VER n_joints"))
    if kind == "HEL" and n == 3:
        return Hello(_hex(fields[1], "HEL nonce"), _hex(fields[2], "HEL request"))
    if kind == "HEL" and n == 4:
        return HelloReply(_hex(fields[1], "HEL nonce"), _hex(fields[2], "HEL proof"), _clock_ms(fields[3]))
    if kind == "AUT" and n == 2:
        return Authenticate(_hex(fields[1], "AUT proof"))
    if kind == "RQJ" and n == 1:
        return RequestJoints()
    if kind == "STP" and n == 1:
        return Stop()
    if kind == "HBT" and n == 2:
        timeout = _integer(fields[1], "HBT timeout_ms")
        if timeout > 60_000:
            raise ProtocolError("malformed", f"HBT timeout {timeout} ms above 60000 ms")
        return Heartbeat(timeout)
    if kind == "STR" and n == 2:
        hz = _number(fields[1], "STR hz")
        if hz < 0:
            raise ProtocolError("malformed", f"STR hz must be >= 0, got {hz}")
        return Stream(hz)
    if kind == "MVJ":
        if not 3 <= n <= 2 + MAX_JOINTS:
            raise ProtocolError("malformed", f"MVJ needs an id and 1 to {MAX_JOINTS} joint values; got {n} fields")
        return MoveJoints(
            _token(fields[1], "MVJ id"), tuple(_number(f, f"MVJ q{i + 1}") for i, f in enumerate(fields[2:]))
        )
    if kind in ("JNT", "ACK", "DON", "STA", "ERR", "RQJ", "STR", "MVJ", "VER", "STP", "HBT", "HEL", "AUT"):
        raise ProtocolError("malformed", f"{kind} with {n - 1} fields")
    raise ProtocolError("unknown", f"unknown sentence type {kind!r}")
