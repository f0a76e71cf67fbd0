"""Exceptions a user can cause. Each names the file, field or point involved.

The window shows them as messages, the command line prints one line and exits 2;
neither shows a traceback for these.
"""

from __future__ import annotations

from pathlib import Path


class VideocalError(Exception):
    """Base class of every error videocal raises on purpose."""


class FileFormatError(VideocalError, ValueError):
    """A file could not be read: missing, unreadable, malformed, or of an unknown kind.

    ``path`` is the file, ``field`` the offending key path (``"camera_matrix.data[3]"``)
    or ``None`` when the whole file is at fault.
    """

    def __init__(self, path: str | Path, message: str, field: str | None = None):
        self.path = Path(path)
        self.field = field
        self.detail = message
        where = f"{self.path}: field '{field}': " if field else f"{self.path}: "
        super().__init__(where + message)


class FileWriteError(VideocalError, OSError):
    """A file could not be written (no such folder, no permission, disk full); ``path`` is the file."""

    def __init__(self, path: str | Path, message: str):
        self.path = Path(path)
        super().__init__(f"{self.path}: {message}")

    def __str__(self) -> str:
        return str(self.args[0])


class OperatorError(VideocalError, ValueError):
    """An action that cannot be taken now (nothing picked, no camera frame, a recording open...);
    the message says what to do instead."""


class UnknownNameError(VideocalError, KeyError):
    """A name (component, task location, feature, pair) that is not there; the message lists the known ones."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""
