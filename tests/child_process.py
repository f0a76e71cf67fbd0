"""A videocal command run as a child process by a test, whose threads are shown if it hangs: a child that outlives
its time is sent SIGABRT, Python's fault handler writes every thread's stack to its stderr, and the test fails with
that stderr instead of pytest's own timeout ending the test with the child's output lost."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

HANG_S = 240.0
"""Longer than any demo takes on a loaded machine (17-45 s), shorter than pytest's own timeout (300 s)."""


def run_videocal(args: list[str], timeout_s: float = HANG_S, env: dict | None = None) -> subprocess.CompletedProcess:
    """``python -m app.cli.main *args``; its completed process, or a failed test showing where a hung child waits."""
    import pytest

    child = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**(env or os.environ), "PYTHONFAULTHANDLER": "1"},
    )
    try:
        out, err = child.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        child.send_signal(signal.SIGABRT)
        try:
            out, err = child.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            child.kill()
            out, err = child.communicate()
        pytest.fail(f"videocal {' '.join(args)} still ran after {timeout_s:.0f} s; its threads:\n{err[-6000:]}")
    return subprocess.CompletedProcess(child.args, child.returncode, out, err)
