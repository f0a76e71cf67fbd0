"""The controller simulator as a real subprocess, for the link tests."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path


class SimProcess:
    """``videocal sim-controller`` running in the background; ``url`` is what it serves."""

    def __init__(self, *args: str, link: Path | None = None):
        cmd = [sys.executable, "-m", "app.cli.main", "sim-controller", "--robot", "plain", *args]
        if link is not None:
            cmd += ["--link", str(link)]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline().strip()
        if not line:
            raise RuntimeError(f"simulator did not start: {self.proc.stderr.read()}")
        self.device = line
        self.url = str(link) if link is not None else line

    def next_announcement(self, timeout_s: float = 5.0) -> str:
        deadline = time.monotonic() + timeout_s
        line = self.proc.stdout.readline().strip()
        if time.monotonic() > deadline:
            raise TimeoutError("no new device path")
        return line

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        for stream in (self.proc.stdout, self.proc.stderr):
            stream.close()
