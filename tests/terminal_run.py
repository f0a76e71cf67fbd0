"""A command run as from a user's shell: standard error on a pseudo-terminal, standard output on a pipe."""

from __future__ import annotations

import os
import pty
import subprocess
import sys


def run_on_terminal(args: list[str], timeout: float = 300.0) -> tuple[int, str, str]:
    """The CLI with standard error on a pseudo-terminal (as a user's shell gives it), standard output on a pipe:
    ``(exit code, stdout, what the terminal received)``."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", *args],
        stdout=subprocess.PIPE,
        stderr=slave,
        env={**os.environ, "QT_QPA_PLATFORM": "offscreen"},
    )
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 65536)
        except OSError:  # the child closed the terminal (EIO)
            break
        if not data:
            break
        chunks.append(data)
    out, _ = proc.communicate(timeout=timeout)
    os.close(master)
    return proc.returncode, out.decode(), b"".join(chunks).decode(errors="replace")
