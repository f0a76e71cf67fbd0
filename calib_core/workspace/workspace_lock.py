"""One window at a time on a workspace file: a lock beside it (``.<name>.lock``, ``flock``), held while a window has
the workspace open or has saved to it. A second window that opens or saves the same file is told who holds it, and
nothing is written: two windows saving one file silently overwrote each other's pairs and corrections. The lock goes
with the process that holds it (a crashed window holds nothing), and the file beside the workspace stays (empty of
meaning once unlocked)."""

from __future__ import annotations

import fcntl
import os
import time
from pathlib import Path

from calib_core.errors import FileWriteError, OperatorError


class WorkspaceInUse(OperatorError):
    """Another videocal process holds the workspace; the message names it."""


def lock_path(workspace: Path) -> Path:
    return workspace.with_name(f".{workspace.name}.lock")


class WorkspaceLock:
    """The lock on ``workspace`` (an absolute path), taken at once or :class:`WorkspaceInUse`."""

    def __init__(self, workspace: str | Path):
        self._fd: int | None = None
        self.workspace = Path(workspace).resolve()
        self.path = lock_path(self.workspace)
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o600)
        except OSError as exc:  # a read-only or missing folder, a full disk: said before anything is written
            raise FileWriteError(
                self.workspace, f"cannot save here: the lock beside it cannot be made ({exc.strerror or exc})"
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 200).decode("utf-8", "replace").strip() or "another videocal window"
            os.close(fd)
            raise WorkspaceInUse(
                f"{self.workspace} is open in {holder}: saving here would overwrite its work "
                "(save this one under another name, or close the other window first)"
            ) from None
        except OSError:
            os.close(fd)
            raise
        self._fd = fd
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"videocal (pid {os.getpid()}, since {time.strftime('%H:%M:%S')})".encode())
        except OSError:
            pass  # a full disk: the lock holds without its note of who holds it

    def release(self) -> None:
        if self._fd is not None:
            fcntl.flock(self._fd, fcntl.LOCK_UN)
            os.close(self._fd)
            self._fd = None

    def __del__(self):  # a lock nobody releases goes with its object
        self.release()
