"""Write files so that a crash leaves either the old file or the new one, never half of one.

One writer for every file the program writes. It writes beside the target, checks what was written
(its size, and a caller's ``check`` that reads it back: a library that hides its write errors, as
``cv2.FileStorage`` does on a full disk, is caught there), keeps the old file's permissions, writes
through a symlink to its target (the link stays a link), and reports a failure (a full disk, a
read-only folder) as :class:`~calib_core.errors.FileWriteError` with the old file intact.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from calib_core.errors import FileWriteError


@contextlib.contextmanager
def atomic_path(
    path: str | Path, check: Callable[[Path], None] | None = None, *, may_be_empty: bool = False
) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    The caller writes the temporary file by any means (e.g. ``cv2.FileStorage``); ``check(tmp)``
    then reads it back and raises if it is not what was meant (an empty file always fails). If
    anything raises, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(os.path.realpath(path)) if Path(path).is_symlink() else Path(path)
    try:
        fd, tmp_name = tempfile.mkstemp(
            prefix=f".{target.name}.", suffix=".tmp" + target.suffix, dir=target.parent or "."
        )
    except OSError as exc:
        raise FileWriteError(target, f"cannot write here: {exc.strerror or exc}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        if tmp.stat().st_size == 0 and not may_be_empty:
            raise FileWriteError(
                target, "not written (the old file, if any, is unchanged): nothing reached the disk (is it full?)"
            )
        if check is not None:
            try:
                check(tmp)
            except Exception as exc:  # whatever the reader raises, the file is not what was meant
                raise FileWriteError(
                    target,
                    "not written (the old file, if any, is unchanged): what reached the disk does not read back "
                    f"({exc})",
                ) from None
        _keep_mode(target, tmp)
        os.replace(tmp, target)
        _fsync_dir(target.parent)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise FileWriteError(
            target, f"not written (the old file, if any, is unchanged): {exc.strerror or exc}"
        ) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temp file, fsync, rename), checked by reading it back."""

    def same(tmp: Path) -> None:
        if tmp.read_bytes() != data:
            raise ValueError(f"{tmp.stat().st_size} of {len(data)} bytes")

    with atomic_path(path, same, may_be_empty=not data) as tmp:
        tmp.write_bytes(data)


def _keep_mode(target: Path, tmp: Path) -> None:
    """The new file gets the old one's permissions (or the user's default: mkstemp makes it 0600)."""
    try:
        mode = stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.chmod(tmp, mode)


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically (temp file, fsync, rename)."""
    atomic_write_bytes(path, text.encode(encoding))


def _fsync_dir(folder: Path) -> None:
    # The rename itself is durable only once the directory entry is flushed.
    with contextlib.suppress(OSError):
        fd = os.open(folder or ".", os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
