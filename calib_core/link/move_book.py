"""The driver's book of moves in flight: which ``MVJ`` the controller has acknowledged, which
reply ends which move, which ran out of time. Thread-safe; handles are finished outside the lock."""

from __future__ import annotations

import re
import threading
from collections import deque

from calib_core.connectors.link_types import MoveError, MoveHandle, MoveTimeout
from calib_core.link.protocol import ErrorReply

_MOVE_IN_ERROR = re.compile(r"move ([A-Za-z0-9_.-]+):")


class MoveBook:
    def __init__(self):
        self._lock = threading.Lock()
        self._moves: dict[str, MoveHandle] = {}
        self._awaiting_ack: deque[MoveHandle] = deque()

    def __bool__(self) -> bool:
        return bool(self._moves)

    def add(self, handle: MoveHandle) -> None:
        with self._lock:
            self._moves[handle.id] = handle
            self._awaiting_ack.append(handle)

    def withdraw(self, handle: MoveHandle) -> None:
        """Forget a move that was never sent."""
        with self._lock:
            self._drop(handle)

    def _drop(self, handle: MoveHandle) -> None:
        self._moves.pop(handle.id, None)
        if handle in self._awaiting_ack:
            self._awaiting_ack.remove(handle)

    def acknowledged(self, move_id: str) -> MoveHandle | None:
        """An ``ACK,MVJ``: the move it names, now acknowledged (``None``: no such move in flight, or acknowledged
        before)."""
        with self._lock:
            handle = self._moves.get(move_id)
            if handle is None or handle.acked:
                return None
            handle.acked = True
            if handle in self._awaiting_ack:
                self._awaiting_ack.remove(handle)
            return handle

    def done(self, move_id: str) -> str | None:
        """A ``DON``: finishes the move; returns why it was not believed (no ``ACK`` came first)."""
        with self._lock:
            handle = self._moves.get(move_id)
            if handle is None:
                return None
            if not handle.acked:
                return f"DON for move {move_id} without its ACK: ignored"
            self._drop(handle)
        handle._finish()
        return None

    def refused(self, msg: ErrorReply) -> bool:
        """An ``ERR``: it ends the move it names (``move <id>: ...``) and nothing else. An error naming no move may
        answer another writer on the line (a second client's malformed sentence, an old-style hello): taken as the
        oldest move's refusal it once told the operator a move was refused that the robot went on to make. A move
        refused without its name ends at its timeout, as one the controller never answered. True: it ended one."""
        named = _MOVE_IN_ERROR.match(msg.text)
        if not named:
            return False
        with self._lock:
            handle = self._moves.get(named.group(1))
            if handle is None:
                return False
            self._drop(handle)
        handle._finish(MoveError(f"move {handle.id} refused by the controller: {msg.code}: {msg.text}"))
        return True

    def expire(self, now_s: float) -> None:
        """Finish every move whose deadline (host monotonic s) has passed with :class:`MoveTimeout`."""
        with self._lock:
            expired = [h for h in self._moves.values() if now_s > h.deadline_s]
            for handle in expired:
                self._drop(handle)
        for handle in expired:
            what = "no DON" if handle.acked else "no ACK"
            handle._finish(MoveTimeout(f"move {handle.id}: {what} before its timeout"))

    def finish_all(self, why: str) -> None:
        with self._lock:
            handles = list(self._moves.values())
            self._moves.clear()
            self._awaiting_ack.clear()
        for handle in handles:
            handle._finish(MoveError(f"move {handle.id}: {why}"))
