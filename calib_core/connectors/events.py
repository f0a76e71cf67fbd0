"""What every controller connector has in common: its three events, its state, and the single move it follows
(for connectors whose controller takes one move at a time and answers none: ROS 2's topic, URScript)."""

from __future__ import annotations

import threading

from psygnal import Signal

from calib_core.connectors.link_types import LinkState, LinkStats, MoveError, MoveHandle


class ConnectorEvents:
    """``sample_received(TimedSample)``, ``state_changed(LinkState, reason)``, ``auth_changed(state, failure)``;
    a slot that raises is counted in ``stats.errors`` (``last_error`` says which) and never ends the connector."""

    sample_received = Signal(object)
    state_changed = Signal(object, str)
    auth_changed = Signal(object, object)

    stats: LinkStats
    last_error: str | None = None
    _state: LinkState = LinkState.CLOSED

    publishes_transforms: bool = False
    """The connector can put the calibration's results where the robot's software reads them
    (:meth:`publish_static_transforms`: ROS 2's ``/tf_static``); the core publishes to it only then."""

    def publish_static_transforms(self, transforms: list) -> None:
        """``(parent, child, child2parent (4, 4) mm)`` to the robot's side; only when :attr:`publishes_transforms`."""
        raise NotImplementedError(f"{type(self).__name__} does not publish transforms")

    @property
    def state(self) -> LinkState:
        return self._state

    @property
    def delay_s(self) -> float | None:
        """The link's one-way delay (s) where the connector measures it, else ``None``."""
        return None

    def stale_after_now_s(self) -> float:
        """No joint sample for this long marks the link stale by the connector's own rule now (s; a far link's
        includes its spread of delays); 0 where the connector has no such rule."""
        return 0.0

    def _set_state(self, state: LinkState, reason: str) -> None:
        if state is self._state:
            return
        self._state = state
        self._emit(self.state_changed, state, reason)

    def _restate(self, reason: str) -> None:
        """The state as it is, with a new reason: what the user needs to know has changed, the state has not."""
        self._emit(self.state_changed, self._state, reason)

    def _emit(self, signal, *args) -> None:
        try:
            signal.emit(*args)
        except Exception as exc:  # a caller's bug must not kill the link
            self.stats.errors += 1
            self.last_error = f"{signal.name} slot failed: {exc!r}"


class SingleMove:
    """The one move in flight: a new one replaces it (the controller does the same), it ends exactly once."""

    def __init__(self):
        self._lock = threading.Lock()
        self._move: MoveHandle | None = None

    @property
    def current(self) -> MoveHandle | None:
        return self._move

    def begin(self, handle: MoveHandle) -> None:
        self.finish(MoveError("a newer move replaced it"))
        with self._lock:
            self._move = handle

    def finish(self, error: MoveError | None) -> None:
        """End the move in flight: done (``None``) or with ``error`` (its type kept, the move's id put first)."""
        with self._lock:
            move, self._move = self._move, None
        if move is not None and not move.finished:
            move._finish(type(error)(f"move {move.id}: {error}") if error is not None else None)
