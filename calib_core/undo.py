"""Undoable commands on one stack: every operator edit is a command with do and undo."""

from __future__ import annotations

from psygnal import Signal


class Command:
    """An edit. ``label`` names it in the Edit menu (``"Add pair 3"``). A command checks itself (:meth:`check`)
    when pushed: the checks of an edit live in its command, once, whoever makes it (a button, the command line, a
    script)."""

    label = "edit"

    def check(self) -> None:
        """Raise an error saying what is wrong (and what to do instead) when the edit cannot be made now; called by
        :meth:`UndoStack.push` before :meth:`do`, so a refused edit changes nothing."""

    @property
    def changes_nothing(self) -> bool:
        """Whether doing it would leave everything as it is (an option set to the value it has): such a command is
        not pushed."""
        return False

    def do(self) -> None:
        raise NotImplementedError

    def undo(self) -> None:
        raise NotImplementedError

    def merge(self, later: "Command") -> bool:
        """Absorb ``later`` (already done) into this command, so one undo reverts both; False: keep apart."""
        return False


class UndoStack:
    """Executes commands and keeps them for undo and redo. Events (psygnal): ``applied(command)`` after a command
    was done, undone or redone (its effects in place: whoever keeps other state in step with an edit listens here);
    ``changed()`` after every push, undo, redo or clear."""

    applied = Signal(object)
    changed = Signal()

    def __init__(self, limit: int = 500):
        self._done: list[Command] = []
        self._undone: list[Command] = []
        self._limit = limit

    def _changed(self) -> None:
        self.changed.emit()

    def push(self, command: Command) -> Command:
        """Check ``command``, do it and record it (clears the redo history); returns it (a pick's number is on it).
        A command the last one can :meth:`~Command.merge` (the same spin box turned again) joins it as one undo
        step; one that :attr:`~Command.changes_nothing` is neither done nor recorded."""
        command.check()
        if command.changes_nothing:
            return command
        command.do()
        self.applied.emit(command)
        if self._done and not self._undone and self._done[-1].merge(command):
            self._changed()
            return command
        self._done.append(command)
        del self._done[: -self._limit]
        self._undone.clear()
        self._changed()
        return command

    def undo(self) -> str | None:
        """Undo the last command; its label, or None when there is nothing to undo."""
        if not self._done:
            return None
        command = self._done.pop()
        command.undo()
        self.applied.emit(command)
        self._undone.append(command)
        self._changed()
        return command.label

    def redo(self) -> str | None:
        if not self._undone:
            return None
        command = self._undone.pop()
        command.do()
        self.applied.emit(command)
        self._done.append(command)
        self._changed()
        return command.label

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    @property
    def undo_label(self) -> str | None:
        return self._done[-1].label if self._done else None

    @property
    def redo_label(self) -> str | None:
        return self._undone[-1].label if self._undone else None

    def clear(self) -> None:
        self._done.clear()
        self._undone.clear()
        self._changed()
