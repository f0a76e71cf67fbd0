"""Names from the user (task locations, components, features, files): checked where they enter.

A name travels into places where a stray character is code: a controller listing's comment (a newline
in a task name once exported ``:= 0; END; DELETE`` as PDL2 statements), a YAML key, a CSV cell, a
window's label. Every reader and editor takes names through :func:`check_name`; the exporters check
again before they write one.
"""

from __future__ import annotations

import unicodedata

from calib_core.errors import OperatorError

MAX_NAME_CHARS = 100

EDITOR_FORBIDDEN = "\n\r\t:#{}[],&*!|>'\"%@`"
"""Characters a name typed in the window may not hold (they mean something in the workcell's YAML)."""


class InvalidNameError(OperatorError):
    """A name that cannot be used; the message names it and says why."""


def name_problem(name) -> str | None:
    """Why ``name`` is not a usable name (``None``: it is): not text, empty, too long, leading or
    trailing spaces, or a control or format character (a newline, a tab, a bidi override...)."""
    if not isinstance(name, str):
        return f"must be text, got {type(name).__name__}"
    if not name.strip():
        return "must not be empty"
    if len(name) > MAX_NAME_CHARS:
        return f"is {len(name)} characters long; at most {MAX_NAME_CHARS}"
    if name != name.strip():
        return "must not start or end with spaces"
    for c in name:
        if unicodedata.category(c)[0] == "C" or unicodedata.category(c) in ("Zl", "Zp"):
            return f"holds the control character U+{ord(c):04X}"
    return None


def check_name(name, what: str) -> str:
    """``name`` if it is usable, else :class:`InvalidNameError` naming ``what`` it was for."""
    why = name_problem(name)
    if why is not None:
        raise InvalidNameError(f"{what} name {str(name)[:60]!r} {why}")
    return name


def check_typed_name(name, what: str) -> str:
    """A name typed in the window: :func:`check_name`, and none of :data:`EDITOR_FORBIDDEN`."""
    name = check_name(str(name).strip(), what)
    if any(c in name for c in EDITOR_FORBIDDEN):
        raise InvalidNameError(f"{what} name {name!r}: use letters, digits, '_', '-', '.' or spaces")
    return name


MAX_NOTE_CHARS = 4000
"""The longest note (a correction's source, who confirmed it and why) a file may hold."""


def one_line(text: str) -> str:
    """``text`` as one line: every control or line-break character a space (a note written into an export's remark
    must not start a statement on the next line)."""
    return "".join(
        " " if unicodedata.category(c)[0] == "C" or unicodedata.category(c) in ("Zl", "Zp") else c for c in text
    )


def note_problem(text) -> str | None:
    """Why ``text`` is not a usable note (``None``: it is): not text, too long, or a control character."""
    if not isinstance(text, str):
        return f"must be text, got {type(text).__name__}"
    if len(text) > MAX_NOTE_CHARS:
        return f"is {len(text)} characters long; at most {MAX_NOTE_CHARS}"
    if one_line(text) != text:
        c = next(c for c, d in zip(text, one_line(text)) if c != d)
        return f"holds the control character U+{ord(c):04X}"
    return None
