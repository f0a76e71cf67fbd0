"""A second process keeping one core busy: the 'loaded' columns of the benches (a build or another program
running beside videocal on the operator's machine)."""

from __future__ import annotations

import subprocess
import sys
from contextlib import contextmanager


@contextmanager
def busy_core():
    """One core spinning in a child process for the ``with`` block; gone after it, whatever happened inside."""
    hog = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        yield
    finally:
        hog.kill()
        hog.wait()
