"""The serial driver of the controller link: a reader thread over anything pyserial's
``serial_for_url`` opens (a port, a pty, ``socket://``, ``rfc2217://``, ``loop://``).

It polls (``$RQJ`` at a rate: the paper's cyclic request) or asks for a stream (``$STR``);
assembles sentences from a dirty line; delivers each joint sample once, in order; watches
for staleness; when the device disappears it reports it and reconnects with backoff,
keeping the caller's state (callbacks, statistics, pending moves); tracks moves (MVJ with
ACK/DON, ERR and timeouts). Nothing blocks the caller's thread and no exception escapes
the reader thread except as a reported error. :meth:`ControllerLink.close` returns within 1 s.
"""

from __future__ import annotations

import itertools
import secrets
import threading
import time
from collections import deque
import serial

from calib_core.connectors.events import ConnectorEvents
from calib_core.link.assembler import SentenceAssembler
from calib_core.link.link_key import default_key_path, user_key
from calib_core.connectors.link_types import LinkError, LinkState, LinkStats, MoveError, MoveHandle, TimedSample
from calib_core.link.move_book import MoveBook
from calib_core.link.sample_order import SampleOrder
from calib_core.link.protocol import (
    Ack,
    Done,
    ErrorReply,
    HelloReply,
    JointSample,
    MoveJoints,
    ProtocolError,
    RequestJoints,
    RequestState,
    RequestVersion,
    StateReport,
    Stop,
    Heartbeat,
    Stream,
    VersionReport,
    encode,
    parse_body,
)

from calib_core.link.round_trip import RoundTrip
from calib_core.link.workstation_auth import AuthState, WorkstationAuth, handshake_budget_s

HANDSHAKE_WAIT_S = handshake_budget_s() + 0.5
"""How long a move waits for a handshake under way (its retries included) before it is not sent."""

PING_EVERY_S = 2.0
"""With no other reply timed for this long, a ``$STA`` times the round trip (the link's delay can change)."""

_READ_TIMEOUT_S = 0.01
_BACKOFF_S = (0.05, 0.1, 0.2, 0.4, 0.8, 1.0)
MODES = ("poll", "stream")


class ControllerLink(ConnectorEvents):
    """The connector of videocal's own protocol (``videocal.controllers``: a port path, ``serial://``,
    ``socket://``, ``rfc2217://``, ``loop://``): a link to one controller. ``mode``: ``poll`` or ``stream`` at
    ``rate_hz``;
    ``stale_after_s``: no sample for this long marks the link stale (default: five periods,
    at least 0.25 s); ``n_joints``: how many joints the robot has (samples with another count are
    counted in ``stats.wrong_joint_count`` and not delivered; ``None`` takes any count).
    ``key``: the link's pre-shared key (32 bytes); ``"user"`` (default) the user's
    (:func:`~calib_core.link.link_key.user_key`); ``None`` for a protocol-3 controller without
    authentication. With a key every (re)connection opens an authenticated session, and moves are
    sent sealed, or not at all (``auth_state``, ``auth_failure``).
    Serial settings (``baudrate``, ``parity``...) pass to pyserial.

    Events (psygnal, emitted on the reader thread; keep slots short, a slot that raises is counted
    in ``stats.errors`` and does not stop the link): ``sample_received(TimedSample)`` for every
    delivered sample, ``state_changed(LinkState, reason)`` on a change of state,
    ``auth_changed(AuthState, failure)`` when a handshake ends (``ready`` or ``failed``).

    Far controllers: every timeout follows the measured round trip (:attr:`round_trip`, timed on the
    handshake, move acknowledgements and a ``$STA`` every :data:`PING_EVERY_S` when nothing else was): the
    dead-man time sent to the controller is ``deadman_ms`` plus the round trip's timeout (a heartbeat
    held up on a slow link is no reason to stop the robot), a link is stale only after ``stale_after_s``
    plus the round trip's spread, and a hello waits at least the round trip's timeout.

    Its public members are the connector protocol (start, close, latest, delay_s, stats_snapshot, move_joints, stop),
    the protocol's own requests (state, version, samples), the dead-man and staleness read-outs, the authentication
    state and the configuration read from its URL."""

    def __init__(
        self,
        url: str,
        *,
        mode: str = "stream",
        rate_hz: float = 50.0,
        stale_after_s: float | None = None,
        queue_size: int = 10_000,
        reconnect: bool = True,
        n_joints: int | None = None,
        deadman_ms: int = 1000,
        key: bytes | str | None = "user",
        **serial_settings,
    ):
        if mode not in MODES:
            raise ValueError(f"mode must be 'poll' or 'stream', got {mode!r}")
        if not (0 < rate_hz <= 250):
            raise ValueError(f"rate must lie in (0, 250] Hz, got {rate_hz}")
        self.url = url
        self.n_joints = n_joints
        if not (0 <= deadman_ms <= 60_000):
            raise ValueError(f"the dead-man time must lie in [0, 60000] ms, got {deadman_ms}")
        self.deadman_ms = int(deadman_ms)
        """The controller stops a move when no heartbeat came for this long (0: no dead-man)."""
        self.mode = mode
        self.rate_hz = float(rate_hz)
        self.stale_after_s = stale_after_s if stale_after_s is not None else max(5.0 / rate_hz, 0.25)
        self.reconnect = reconnect
        self._serial_settings = {"baudrate": 115200, **serial_settings}
        try:
            serial.serial_for_url(url, do_not_open=True, **self._serial_settings)
        except (ValueError, serial.SerialException) as exc:
            raise LinkError(f"unusable link URL {url!r}: {exc}") from None
        self.stats = LinkStats()
        self._state = LinkState.CLOSED
        self._lock = threading.Lock()
        self._write_lock = threading.Lock()
        self._queue: deque[TimedSample] = deque(maxlen=queue_size)
        self._latest: TimedSample | None = None
        self._order = SampleOrder(self.stats)
        self._moves = MoveBook()
        self.round_trip = RoundTrip()
        """The measured round trip to the controller (s): what the timeouts follow."""
        self._pings: deque[float] = deque(maxlen=8)
        if key == "user":
            self._auth = WorkstationAuth(user_key(), f"the link key in {default_key_path()}", self.round_trip)
        elif key is None or isinstance(key, bytes):
            self._auth = WorkstationAuth(key, round_trip=self.round_trip)
        else:
            raise ValueError(f"key: 32 bytes, 'user' or None, got {type(key).__name__}")
        self._auth.settled.connect(lambda state, failure: self._emit(self.auth_changed, state, failure))
        self.joint_map = None
        """The cell's map between model joints and this controller's axes (set by the connector's opener)."""
        self._next_hello_s = 0.0
        self._state_reports: deque[StateReport] = deque(maxlen=16)
        self._version_reports: deque[VersionReport] = deque(maxlen=4)
        self._state_event = threading.Condition(self._lock)
        self._ids = itertools.count(1)
        self._session = secrets.token_hex(2)  # move ids unique across processes: "<session>.<n>"
        self._port: serial.SerialBase | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._assembler = SentenceAssembler()
        self.last_error: str | None = None

    # --- life cycle ------------------------------------------------------------------------
    def start(self, *, wait_open: bool = False) -> ControllerLink:
        """Start the reader thread. With ``wait_open``, open the device here first and raise
        :class:`LinkError` if that fails (a command line wants to know at once)."""
        if self._thread is not None:
            return self
        if wait_open:
            self._port = self._open()
            self._on_open()
        else:
            self._set_state(LinkState.CONNECTING, "opening")
        self._thread = threading.Thread(target=self._run, name=f"controller-link {self.url}", daemon=True)
        self._thread.start()
        if wait_open:
            self._auth.wait_settled(2.0)
        return self

    def close(self) -> None:
        """Stop the thread and close the device (within about 1 s). A move still running is stopped
        first (``$STP``): a workstation that goes away leaves no robot moving."""
        if self._moves:
            self._send(Stop().body())
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        self._close_port()
        self._set_state(LinkState.CLOSED, "closed by the caller")
        self._moves.finish_all("the link was closed")

    def __enter__(self) -> ControllerLink:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()

    # --- what callers read ---------------------------------------------------------------
    @property
    def auth_state(self) -> AuthState:
        """Whether moves can be sent: ``ready`` (sealed), ``off`` (no key), ``pending`` or ``failed``."""
        return self._auth.state

    @property
    def auth_failure(self) -> str | None:
        """Why the session could not be opened (the controller's key, protocol or silence)."""
        return self._auth.failure

    @property
    def latest(self) -> TimedSample | None:
        return self._latest

    @property
    def delay_s(self) -> float | None:
        """The link's one-way delay (s): half the measured round trip; ``None`` before one was measured."""
        return self.round_trip.one_way_s()

    def deadman_sent_ms(self) -> int:
        """The dead-man time the heartbeats carry (ms): ``deadman_ms`` plus the round trip's timeout."""
        return min(60_000, self.deadman_ms + int(1000 * self.round_trip.rto_s))

    def stale_after_now_s(self) -> float:
        """No sample for this long marks the link stale (s): ``stale_after_s`` plus the round trip's spread."""
        return self.stale_after_s + self.round_trip.spread_s

    def drain(self) -> list[TimedSample]:
        """Every sample queued since the last drain, oldest first."""
        with self._lock:
            out = list(self._queue)
            self._queue.clear()
        return out

    def stats_snapshot(self) -> dict[str, int]:
        with self._lock:
            return self.stats.as_dict()

    # --- commands --------------------------------------------------------------------------
    def move_joints(self, joints_deg, *, timeout_s: float = 60.0) -> MoveHandle:
        """Send ``$MVJ`` (sealed) and return its handle at once. While the handshake is under way this
        waits for it (at most 1 s); without an authenticated session the move is not sent and the
        handle has finished with the reason."""
        q = tuple(float(v) for v in joints_deg)
        if self.n_joints is not None and len(q) != self.n_joints:
            raise ValueError(f"a move needs {self.n_joints} joint values, got {len(q)}")
        if not all(abs(v) < 1e6 for v in q):
            raise ValueError(f"a move needs finite joint values within 1e6, got {q}")
        handle = MoveHandle(f"m{self._session}.{next(self._ids)}", q, time.monotonic() + timeout_s)
        if self._auth.wait_settled(HANDSHAKE_WAIT_S) not in (AuthState.READY, AuthState.OFF):
            handle.sent = False
            if self._auth.state is AuthState.PENDING and self._state is not LinkState.UP:
                # (a link that dropped starts its next handshake when it is back: the reason is the link, not that)
                handle._finish(MoveError(f"move {handle.id}: the link is {self._state.value}; nothing was sent"))
            else:
                handle._finish(MoveError(f"move {handle.id}: not sent: {self._auth.why_not}"))
            return handle
        self._moves.add(handle)
        handle.sent_s = time.monotonic()
        if not self._send(MoveJoints(handle.id, q).body(), sealed=True):
            self._moves.withdraw(handle)
            handle.sent = False
            handle._finish(MoveError(f"move {handle.id}: the link is {self._state.value}; nothing was sent"))
        return handle

    def stop(self) -> bool:
        """``$STP``: the controller stops the robot where it is; the running move ends with its
        ``ERR,STOPPED``. True if the sentence went out."""
        return self._send(Stop().body())

    def request_state(self, timeout_s: float = 1.0) -> StateReport | None:
        """Ask ``$STA`` and wait for the report (``None`` on timeout)."""
        return self._ask(RequestState().body(), self._state_reports, timeout_s)

    def request_version(self, timeout_s: float = 1.0) -> VersionReport | None:
        """Ask ``$VER``: the controller's protocol version and joint count (``None`` on timeout;
        a version-1 controller answers ``ERR,UNKNOWN``, which counts in ``stats.errors``)."""
        return self._ask(RequestVersion().body(), self._version_reports, timeout_s)

    def _ask(self, body: str, replies: deque, timeout_s: float):
        """Send a request and wait for the first reply the reader thread puts in ``replies``."""
        with self._lock:
            replies.clear()
        if self._send(body) and body == RequestState().body():
            self._pings.append(time.monotonic())
        with self._state_event:
            self._state_event.wait_for(lambda: bool(replies), timeout_s)
            return replies.popleft() if replies else None

    def wait_for_samples(self, count: int, timeout_s: float) -> bool:
        """Block until ``count`` samples have been delivered in all (``stats.samples``)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.stats.samples >= count:
                return True
            time.sleep(0.005)
        return self.stats.samples >= count

    # --- internals -------------------------------------------------------------------------
    def _open(self) -> serial.SerialBase:
        try:
            port = serial.serial_for_url(self.url, timeout=_READ_TIMEOUT_S, write_timeout=0.5, **self._serial_settings)
        except (serial.SerialException, OSError, ValueError) as exc:
            raise LinkError(f"cannot open {self.url}: {exc}") from None
        return port

    def _on_open(self) -> None:
        """A fresh connection: forget stale bytes and partial sentences, set the controller's stream."""
        try:
            self._port.reset_input_buffer()
        except (serial.SerialException, OSError, AttributeError):
            pass
        self._assembler.reset()
        self._pings.clear()
        self._set_state(LinkState.CONNECTING, "open, waiting for samples")
        # Polling stops any stream a previous session left running; streaming (re)starts it.
        self._send(Stream(self.rate_hz if self.mode == "stream" else 0).body())
        self._hello()

    def _hello(self) -> None:
        hello = self._auth.hello()
        if hello is not None:
            self._next_hello_s = time.monotonic() + 1.0
            self._send(hello)

    def _close_port(self) -> None:
        port, self._port = self._port, None
        if port is not None:
            try:
                port.close()
            except Exception:  # closing a vanished device may fail in many ways; it is gone either way
                pass

    def _send(self, body: str, *, sealed: bool = False) -> bool:
        port = self._port
        if port is None:
            return False
        try:
            with self._write_lock:  # sealed under the lock: counters go out in order
                port.write(encode(self._auth.seal(body) if sealed else body))
            return True
        except (serial.SerialException, OSError, ValueError) as exc:
            self.last_error = f"write failed: {exc}"
            return False

    def _run(self) -> None:
        backoff = iter(_BACKOFF_S)
        next_poll = 0.0
        next_heartbeat = 0.0
        last_sample_t = time.monotonic()
        while not self._stop.is_set():
            if self._port is None:
                try:
                    self._port = self._open()
                except LinkError as exc:
                    self.last_error = str(exc)
                    self._set_state(LinkState.DOWN, str(exc))
                    self._moves.expire(time.monotonic())  # a move's timeout runs on while the link is down
                    if not self.reconnect:
                        return
                    self._stop.wait(next(backoff, _BACKOFF_S[-1]))
                    continue
                backoff = iter(_BACKOFF_S)
                self._on_open()
                last_sample_t = time.monotonic()
            try:
                port = self._port
                data = port.read(max(1, port.in_waiting))
            except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
                # The device vanished (USB unplugged, controller rebooted, server gone).
                self._close_port()
                with self._lock:
                    self.stats.reconnects += 1
                self.last_error = f"device lost: {exc}"
                self._set_state(LinkState.DOWN, f"device lost: {exc}")
                continue
            now = time.monotonic()
            if data:
                for body in self._assembler.feed(data):
                    if self._dispatch(body, now):
                        last_sample_t = now
                self._sync_counts()
            if self.mode == "poll" and now >= next_poll:
                self._send(RequestJoints().body())
                next_poll = max(next_poll + 1.0 / self.rate_hz, now)
            if self.deadman_ms and now >= next_heartbeat and self._auth.state in (AuthState.READY, AuthState.OFF):
                # five heartbeats per dead-man time: a reader thread that waits for the CPU does not trip it.
                # Sealed in the session: the controller believes no one else's (none is sent without a session).
                self._send(Heartbeat(self.deadman_sent_ms()).body(), sealed=True)
                next_heartbeat = now + self.deadman_ms / 5000.0
            if self._state is LinkState.UP and not self._pings and now - self._last_timed_s > PING_EVERY_S:
                self._last_timed_s = now
                if self._send(RequestState().body()):
                    self._pings.append(now)
            if self._state in (LinkState.UP, LinkState.CONNECTING) and now - last_sample_t > self.stale_after_now_s():
                self._set_state(LinkState.STALE, f"no joint sample for {now - last_sample_t:.2f} s")
                if self.mode == "stream":
                    self._send(Stream(self.rate_hz).body())  # a controller that forgot the stream gets asked again
                    last_sample_t = now
            if self._auth.check_timeout(now):
                self._hello()  # unanswered: once more before giving up
            self._moves.expire(now)

    def _sync_counts(self) -> None:
        c = self._assembler.counts
        with self._lock:
            s = self.stats
            s.garbage_bytes, s.bad_checksum, s.too_long = c.garbage_bytes, c.bad_checksum, c.too_long
            s.sentences = c.sentences
            s.malformed = c.malformed + self._field_errors

    _field_errors = 0

    def _dispatch(self, body: str, t_host: float) -> bool:
        try:
            msg = parse_body(body)
        except ProtocolError as exc:
            with self._lock:
                if exc.kind == "non_finite":
                    self.stats.non_finite += 1
                elif exc.kind == "unknown":
                    self.stats.unknown += 1
                else:
                    self._field_errors += 1
            return False
        if isinstance(msg, JointSample):
            if self.n_joints is not None and len(msg.joints_deg) != self.n_joints:
                with self._lock:
                    self.stats.wrong_joint_count += 1
                self.last_error = (
                    f"the controller reports {len(msg.joints_deg)} joints, the robot has "
                    f"{self.n_joints}: is this the cell's controller?"
                )
                return False
            self._deliver(TimedSample(msg, t_host))
            return True
        if isinstance(msg, Ack) and msg.cmd == "MVJ":
            handle = self._moves.acknowledged(msg.id)
            if handle is not None and handle.sent_s is not None:
                self._timed(t_host - handle.sent_s)
        elif isinstance(msg, Ack) and msg.cmd == "AUT":
            self._auth.on_accepted()
        elif isinstance(msg, HelloReply):
            answer = self._auth.on_hello_reply(msg)
            if answer is not None:
                self._send(answer)
        elif isinstance(msg, Done):
            unbelieved = self._moves.done(msg.id)
            if unbelieved:  # a DON for a move the controller never accepted
                with self._lock:
                    self.stats.errors += 1
                self.last_error = unbelieved
        elif isinstance(msg, ErrorReply):
            with self._lock:
                self.stats.errors += 1
            self.last_error = f"controller error {msg.code}: {msg.text}"
            if not self._auth.on_error(msg) and not msg.text.startswith(("heartbeat:", "auth:")):
                self._moves.refused(msg)  # a refused heartbeat or handshake is no move's answer
            if self._auth.lost_session(msg) and t_host >= self._next_hello_s:
                self._hello()  # the controller restarted and forgot the session: open a new one
        elif isinstance(msg, StateReport):
            if self._pings:  # the controller answers in order: the oldest $STA out is this one's
                self._timed(t_host - self._pings.popleft())
            with self._state_event:
                self._state_reports.append(msg)
                self._state_event.notify_all()
        elif isinstance(msg, VersionReport):
            with self._state_event:
                self._version_reports.append(msg)
                self._state_event.notify_all()
        return False

    _last_timed_s = 0.0

    def _timed(self, rtt_s: float) -> None:
        self.round_trip.add(rtt_s)
        self._last_timed_s = time.monotonic()

    def _deliver(self, sample: TimedSample) -> None:
        with self._lock:
            if not self._order.admit(sample.sample):
                return
            self._latest = sample
            self._queue.append(sample)
            self.stats.samples += 1
        if self._state is not LinkState.UP:
            self._set_state(LinkState.UP, "samples arriving")
        self._emit(self.sample_received, sample)
