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
