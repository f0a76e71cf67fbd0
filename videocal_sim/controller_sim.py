"""The simulated robot controller's logic: it answers the wire protocol like the PDL2 program
of the original system, moves with trapezoidal profiles and streams joint samples.

Transport-free: :meth:`ControllerLogic.handle` turns incoming sentence bodies into replies
and :meth:`ControllerLogic.tick` produces the due stream samples and move completions; the
transports in :mod:`videocal_sim.controller_transport` carry the bytes.
"""

from __future__ import annotations

import re
from collections import deque

import time
from collections.abc import Callable

import numpy as np

from calib_core.link import auth
from calib_core.link.joint_motion import JointModel, PlainJointModel, TrapezoidMove
from calib_core.link.protocol import (
    PROTOCOL_VERSION,
    SEQ_MODULUS,
    Ack,
    Done,
    ErrorReply,
    JointSample,
    MoveJoints,
    Authenticate,
    Hello,
    HelloReply,
    ProtocolError,
    RequestJoints,
    RequestState,
    RequestVersion,
    StateReport,
    Stop,
    Heartbeat,
    Stream,
    VersionReport,
    parse_body,
)

MAX_STREAM_HZ = 250.0
REFUSALS_PER_S = 10
"""Refusals answered a second at most; the rest are counted (``refusals_unanswered``) and not answered."""
KEPT_REFUSALS = 200
"""The latest refusals kept (``auth_refusals``); all are counted (``refusals``): a flood of forged sentences grew the
list without limit (42 to 206 MB in 15 s)."""
SEEN_HELLOS = 16
"""How many of the workstation's latest hello nonces are remembered: a hello seen again is a replay, not answered."""


class ControllerLogic:
    """State of the controller: joints (deg), the current move, the stream rate.

    ``clock`` returns seconds (monotonic); ``t_ms`` in samples counts from start-up.
    ``report_joints`` maps the true joint state to what the encoders report (identity by
    default; the test bed reports commanded joints, which is what a real controller does).

    ``key`` (32 bytes): the link's pre-shared key. With one, the controller speaks protocol 6 and
    obeys a motion sentence and a heartbeat only when sealed in the current session and sealed recently
    (:mod:`calib_core.link.auth`); it answers only hellos from the key's holder, and the dead-man counts by the
    heartbeats' sealed times. Every refusal is counted (``refusals``), the latest :data:`KEPT_REFUSALS` kept in
    ``auth_refusals``; those answered ``ERR,AUTH``, at most :data:`REFUSALS_PER_S` a second, are passed to
    ``on_refusal`` (a flood's log is bounded as its replies are) (a flood of forged sentences must not fill the line the
    workstation's replies travel on). Without a key it is a protocol-3 controller: any client's ``MVJ`` moves it.
    """

    def __init__(
        self,
        joint_model: JointModel | None = None,
        initial_deg=None,
        clock: Callable[[], float] = time.monotonic,
        seq_start: int = 0,
        key: bytes | None = None,
        on_refusal: Callable[[str], None] | None = None,
    ):
        self.model = joint_model or PlainJointModel()
        self.clock = clock
        self.t_start = clock()
        n = len(np.asarray(self.model.lower_limits_deg))
        self.joints_deg = np.zeros(n) if initial_deg is None else np.asarray(initial_deg, dtype=float).copy()
        if self.joints_deg.shape != (n,):
            raise ValueError(f"the controller drives {n} joints; initial joints have {self.joints_deg.size} values")
        self.move: TrapezoidMove | None = None
        self.move_id: str | None = None
        self.stream_hz = 0.0
        self._next_stream_t = 0.0
        self.deadman_s = 0.0  # armed by the first HBT with a timeout: no heartbeat for this long stops a move
        self._last_heartbeat_t = 0.0
        self.seq = seq_start % SEQ_MODULUS
        self.key = key
        self.on_refusal = on_refusal
        self.auth_refusals: deque[str] = deque(maxlen=KEPT_REFUSALS)
        self.refusals = 0
        self.refusals_unanswered = 0
        self._refusal_window = (0.0, 0)  # (start s, refusals answered in it)
        self._seen_hellos: list[str] = []
        self.end_session()

    @property
    def session_open(self) -> bool:
        """An authenticated session is in force."""
        return self._session is not None

    def end_session(self) -> None:
        """Forget the authenticated session (the workstation went away or opened a new one)."""
        self._hello: tuple[str, str, float] | None = None  # (workstation nonce, controller nonce, when) offered
        self._session: bytes | None = None
        self._last_counter = 0
        self.fresh_ms = auth.FRESH_MIN_MS
        self._seal_t_ms: int | None = None

    def clock_ms(self, t: float | None = None) -> int:
        """The controller's clock, ms since start-up (what its samples and the seals are stamped with)."""
        return int(round(((self.clock() if t is None else t) - self.t_start) * 1000.0))

    def _sample(self) -> JointSample:
        sample = JointSample(self.seq, self.clock_ms(), tuple(float(q) for q in self.joints_deg))
        self.seq = (self.seq + 1) % SEQ_MODULUS
        return sample

    def _halt(self, now: float, code: str, why: str) -> list:
        """Stop where the robot is now and end the running move with ``ERR,<code>``."""
        if self.move is None:
            return []
        self.joints_deg = self.move.position(now)
        move_id, self.move, self.move_id = self.move_id, None, None
        return [ErrorReply(code, f"move {move_id}: {why}")]

    def _update_motion(self, now: float) -> list:
        out = []
        if self.move is not None and self.deadman_s > 0 and now - self._last_heartbeat_t > self.deadman_s:
            return self._halt(
                now,
                "DEADMAN",
                f"no heartbeat from the workstation for {1000 * (now - self._last_heartbeat_t):.0f} ms: stopped",
            )
        if self.move is not None:
            self.joints_deg = self.move.position(now)
            if self.move.finished(now):
                self.joints_deg = self.move.goal_deg.copy()
                out.append(Done(self.move_id))
                self.move, self.move_id = None, None
        return out

    def handle(self, body: str) -> list:
        """Replies (messages) to one incoming sentence body."""
        now = self.clock()
        out = self._update_motion(now)
        inner, sealed = auth.split_seal(body)
        try:
            msg = parse_body(inner)
        except ProtocolError as exc:
            code = "UNKNOWN" if exc.kind == "unknown" else "SYNTAX"
            why = str(exc).replace(",", ";").replace("*", "x").replace("$", "S")[:80]
            return out + [ErrorReply(code, f"move {move_id}: {why}" if (move_id := _move_id_of(inner)) else why)]
        if isinstance(msg, RequestJoints):
            out.append(self._sample())
        elif isinstance(msg, Stream):
            if msg.hz > MAX_STREAM_HZ:
                out.append(ErrorReply("RANGE", f"stream rate {msg.hz:g} Hz above {MAX_STREAM_HZ:g} Hz"))
            else:
                self.stream_hz = msg.hz
                self._next_stream_t = now
                out.append(Ack("STR", "-"))
        elif isinstance(msg, RequestVersion):
            out.append(VersionReport(PROTOCOL_VERSION if self.key is not None else 3, len(self.joints_deg)))
        elif isinstance(msg, Hello | Authenticate) and self.key is not None:
            out += self._handshake(msg, now)
        elif isinstance(msg, MoveJoints) and self.key is not None and (why := self._seal_problem(inner, sealed, now)):
            out += self._refuse(f"move {msg.id}: not obeyed: {why}", now)
        elif isinstance(msg, MoveJoints):
            goal = np.asarray(msg.joints_deg, dtype=float)
            lo, hi = np.asarray(self.model.lower_limits_deg), np.asarray(self.model.upper_limits_deg)
            bad = np.flatnonzero((goal < lo) | (goal > hi)) if goal.shape == lo.shape else []
            if goal.shape != lo.shape:
                out.append(ErrorReply("SYNTAX", f"move {msg.id}: {goal.size} joint values for a robot of {lo.size}"))
            elif len(bad):
                j = int(bad[0])
                out.append(
                    ErrorReply(
                        "LIMIT", f"move {msg.id}: joint {j + 1} target {goal[j]:.2f} outside [{lo[j]:.1f}; {hi[j]:.1f}]"
                    )
                )
            elif self.move is not None:
                out.append(ErrorReply("BUSY", f"move {msg.id}: still executing move {self.move_id}"))
            elif self.deadman_s > 0 and now - self._last_heartbeat_t > self.deadman_s:
                out.append(
                    ErrorReply(
                        "DEADMAN",
                        f"move {msg.id}: no heartbeat from the workstation for "
                        f"{1000 * (now - self._last_heartbeat_t):.0f} ms: not moving",
                    )
                )
            else:
                self.move = TrapezoidMove.plan(self.joints_deg, goal, np.asarray(self.model.max_speed_deg_s), now)
                self.move_id = msg.id
                out.append(Ack("MVJ", msg.id))
        elif isinstance(msg, Stop):
            out += self._halt(now, "STOPPED", "stopped by the workstation")
            out.append(Ack("STP", "-"))
        elif isinstance(msg, Heartbeat) and self.key is not None and (why := self._seal_problem(inner, sealed, now)):
            # only the authenticated workstation keeps a move running or disarms the dead-man
            out += self._refuse(f"heartbeat: not obeyed: {why}", now)
        elif isinstance(msg, Heartbeat):
            self.deadman_s = msg.timeout_ms / 1000.0
            # the dead-man counts from when the heartbeat was sealed, not from when it arrived: one held back on the
            # way feeds it only for what is left of its time
            self._last_heartbeat_t = now if self.key is None else min(now, self.t_start + self._seal_t_ms / 1000.0)
        elif isinstance(msg, RequestState):
            state = "MOVING" if self.move is not None else "IDLE"
            out.append(StateReport(state, f"stream {self.stream_hz:g} Hz"))
        elif isinstance(msg, Hello | Authenticate):
            out.append(ErrorReply("UNKNOWN", f"{inner[:3]}: this controller has no link key (protocol 3)"))
        else:
            out.append(ErrorReply("UNEXPECTED", f"{type(msg).__name__} is sent by a controller; not accepted"))
        return out

    def _refuse(self, text: str, now: float) -> list[ErrorReply]:
        """The refusal's reply, or none past :data:`REFUSALS_PER_S` this second (it is still counted)."""
        self.auth_refusals.append(text)
        self.refusals += 1
        start, answered = self._refusal_window
        if now - start >= 1.0:
            start, answered = now, 0
        if answered >= REFUSALS_PER_S:
            self.refusals_unanswered += 1
            self._refusal_window = (start, answered)
            return []
        self._refusal_window = (start, answered + 1)
        if self.on_refusal is not None:
            self.on_refusal(text)
        return [ErrorReply("AUTH", text)]

    def _handshake(self, msg, now: float) -> list:
        if isinstance(msg, Hello):
            if not auth.proof_is_valid(auth.hello_request(self.key, msg.nonce), msg.request):
                # not from the key's holder: answered (rate-limited) and forgotten; the offer in force stays
                return self._refuse(
                    f"hello {msg.nonce}: wrong request: the workstation does not hold this controller's link key", now
                )
            if msg.nonce in self._seen_hellos:
                return []  # a hello of the key's holder seen before: replayed from a capture
            self._seen_hellos = (self._seen_hellos + [msg.nonce])[-SEEN_HELLOS:]
            # The session in force stays until a new handshake completes.
            controller_nonce, clock_ms = auth.new_nonce(), self.clock_ms(now)
            self._hello = (msg.nonce, controller_nonce, now)
            return [
                HelloReply(
                    controller_nonce, auth.controller_proof(self.key, msg.nonce, controller_nonce, clock_ms), clock_ms
                )
            ]
        if self._hello is None:
            return self._refuse("auth: AUT without a HEL first", now)
        ws_nonce, controller_nonce, offered = self._hello
        self._hello = None  # one try per hello
        if not auth.proof_is_valid(auth.workstation_proof(self.key, ws_nonce, controller_nonce), msg.proof):
            return self._refuse("auth: wrong proof: the workstation does not hold this controller's link key", now)
        self._session = auth.session_key(self.key, ws_nonce, controller_nonce)
        self._last_counter = 0
        self.fresh_ms = auth.freshness_bound_ms(1000.0 * (now - offered))
        return [Ack("AUT", "-")]

    def _seal_problem(self, inner: str, sealed: auth.Seal | None, now: float) -> str | None:
        """Why a motion sentence is not to be obeyed (``None``: it is sealed in this session, recently)."""
        if self._session is None:
            return "no authenticated session (send HEL and AUT first)"
        if sealed is None:
            return "the sentence carries no seal"
        if not auth.seal_is_valid(self._session, inner, sealed):
            return "wrong seal (altered, or sealed in another session)"
        if sealed.counter <= self._last_counter:
            return f"counter {sealed.counter} not above {self._last_counter} (a replayed sentence)"
        if (stale := auth.staleness(sealed, self.clock_ms(now), self.fresh_ms)) is not None:
            return stale
        self._last_counter = sealed.counter
        self._seal_t_ms = sealed.t_ms
        return None

    def tick(self) -> list:
        """Messages due now: a finished move's DON and the stream samples."""
        now = self.clock()
        out = self._update_motion(now)
        if self.stream_hz > 0 and now >= self._next_stream_t:
            out.append(self._sample())
            period = 1.0 / self.stream_hz
            self._next_stream_t += period
            if self._next_stream_t < now - period:  # fell behind (a stall): do not burst to catch up
                self._next_stream_t = now + period
        return out

    def next_deadline(self) -> float:
        """When :meth:`tick` next has something to do (monotonic seconds)."""
        deadlines = [self.clock() + 0.05]
        if self.stream_hz > 0:
            deadlines.append(self._next_stream_t)
        if self.move is not None:
            deadlines.append(self.move.t0_s + self.move.duration_s)
            if self.deadman_s > 0:
                deadlines.append(self._last_heartbeat_t + self.deadman_s + 1e-3)
        return min(deadlines)


def _move_id_of(body: str) -> str | None:
    """The id of a move sentence the controller could not read (``MVJ,<id>,...``), when its id is one: a refusal
    names the move it refuses (a workstation ends only the move an error names)."""
    fields = body.split(",")
    if len(fields) >= 2 and fields[0] == "MVJ" and re.fullmatch(r"[A-Za-z0-9_.-]{1,32}", fields[1]):
        return fields[1]
    return None
