"""What the operator should read and what a recording should keep: the one place every part of the
operator core says things. ``message(text)`` is for a status line; ``event(kind, detail)`` is an
operator action or a link change worth recording (``detail``: a dict of plain values)."""

from __future__ import annotations

from psygnal import Signal


class OperatorLog:
    message = Signal(str)
    event = Signal(str, object)

    def say(self, text: str) -> None:
        self.message.emit(text)

    def record(self, kind: str, **detail) -> None:
        self.event.emit(kind, detail)
