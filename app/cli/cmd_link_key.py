"""``videocal link-key``: the pre-shared key of the controller link (protocol 4).

Without options it names the user's key file and the key's fingerprint, making the key on first use.
``--show`` prints the key itself (64 hex digits) to install in the controller program; ``--new``
replaces it (every controller holding the old key must get the new one)."""

from __future__ import annotations

import argparse
import hashlib
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--file", type=Path, help="the key file (default: the user's, in the config folder)")
    parser.add_argument("--new", action="store_true", help="replace the key with a fresh one")
    parser.add_argument(
        "--show",
        action="store_true",
        help="print the key (64 hex digits) for the controller program's link_key constant",
    )


def run(args: argparse.Namespace) -> int:
    from calib_core.link.link_key import default_key_path, read_key, write_new_key

    path = args.file or default_key_path()
    key = write_new_key(path, replace=True) if args.new else (read_key(path) if path.exists() else write_new_key(path))
    if args.show:
        print(key.hex())
    else:
        print(f"link key: {path} (fingerprint {hashlib.sha256(key).hexdigest()[:8]}){' : new' if args.new else ''}")
    return 0
