"""The pre-shared key of the controller link: one per user, in the user's config folder.

The file (``~/.config/videocal/link.key`` on Linux) holds 64 hex digits (32 bytes) on one line;
lines starting with ``#`` are comments. It must be readable by its owner only (mode 0600): a key
others can read lets them move the robot. The same key is installed in the controller program
(``resources/controller/videocal_link.pdl``: the constant ``link_key``; ``videocal link-key`` prints it).
"""

from __future__ import annotations

import os
import secrets
import stat
from pathlib import Path

import platformdirs

from calib_core.errors import VideocalError

KEY_BYTES = 32
_MAX_FILE_BYTES = 4096


class LinkKeyError(VideocalError, ValueError):
    """The link key file is missing, malformed or readable by others; the message names the file."""


def default_key_path() -> Path:
    return Path(platformdirs.user_config_dir("videocal")) / "link.key"


def read_key(path: str | Path | None = None) -> bytes:
    """The key in ``path`` (default: the user's); :class:`LinkKeyError` if missing or unusable."""
    path = Path(path) if path is not None else default_key_path()
    try:
        info = path.stat()
        if info.st_size > _MAX_FILE_BYTES:
            raise LinkKeyError(f"{path}: {info.st_size} bytes is not a link key (64 hex digits)")
        text = path.read_text(encoding="ascii")
    except FileNotFoundError:
        raise LinkKeyError(f"{path}: no link key there; `videocal link-key --new` makes one") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise LinkKeyError(f"{path}: cannot read the link key: {getattr(exc, 'strerror', None) or exc}") from None
    if stat.S_IMODE(info.st_mode) & 0o077:
        raise LinkKeyError(
            f"{path}: the link key is readable by others (mode {stat.S_IMODE(info.st_mode):o}); `chmod 600 {path}`, "
            "and make a new key if others may have read it"
        )
    lines = [line.strip() for line in text.splitlines() if line.strip() and not line.strip().startswith("#")]
    if len(lines) != 1:
        raise LinkKeyError(f"{path}: expected one line of {2 * KEY_BYTES} hex digits, found {len(lines)} lines")
    try:
        key = bytes.fromhex(lines[0])
    except ValueError:
        raise LinkKeyError(f"{path}: the key is not hex digits") from None
    if len(key) != KEY_BYTES:
        raise LinkKeyError(f"{path}: the key has {len(key)} bytes, expected {KEY_BYTES} ({2 * KEY_BYTES} hex digits)")
    return key


def write_new_key(path: str | Path | None = None, *, replace: bool = False) -> bytes:
    """Make a fresh key at ``path`` (mode 0600). Without ``replace`` an existing key is kept and
    returned: two processes creating it at once agree on one key (the file appears whole, once)."""
    path = Path(path) if path is not None else default_key_path()
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.exists() and not replace:
        return read_key(path)
    key = secrets.token_bytes(KEY_BYTES)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        with os.fdopen(fd, "w", encoding="ascii") as fh:
            fh.write("# videocal controller link key: keep it secret; the controller program holds the same\n")
            fh.write(key.hex() + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        if replace:
            os.replace(tmp, path)
        else:
            try:
                os.link(tmp, path)  # fails if another process made one first: then theirs is the key
            except FileExistsError:
                return read_key(path)
    finally:
        tmp.unlink(missing_ok=True)
    return key


def user_key() -> bytes:
    """The user's link key, made on first use."""
    path = default_key_path()
    return read_key(path) if path.exists() else write_new_key(path)
