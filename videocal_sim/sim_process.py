"""The controller simulator as a child process for a cell: ``videocal sim-controller --pty`` with a
stable link path in a private folder. Standard library only, so the window can start it before it
imports anything heavy (the simulator's start-up then overlaps the window's)."""

from __future__ import annotations

import ctypes
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from calib_core.errors import VideocalError

_PROJECT = Path(__file__).resolve().parents[1]
_PR_SET_PDEATHSIG = 1


class SiteError(VideocalError, RuntimeError):
    """A device of the site could not be started; the message says why."""


def _die_with_parent() -> None:  # pragma: no cover - runs in the child before exec
    # The simulator must not outlive the program that started it, even one killed with SIGKILL.
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    except OSError:
        pass


def joints_option(text: str | None, n_joints: int, default):
    """``--joints`` of a simulator: ``n_joints`` numbers separated by commas (deg or mm), or ``default``."""
    import numpy as np

    if not text:
        return default
    try:
        joints = np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise VideocalError(f"--joints: numbers separated by commas, got {text!r}") from None
    if len(joints) != n_joints:
        raise VideocalError(f"--joints: the robot has {n_joints} joints, got {len(joints)} values")
    return joints


def stop_child(process: subprocess.Popen) -> None:
    """Terminate (then kill) a child started by a simulated site; safe to call twice."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=3)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=3)
    if process.stdout is not None:
        process.stdout.close()


class SimulatorProcess:
    """``videocal sim-controller --pty`` for the cell at ``workcell_path``, as a child process with
    a stable link path in a private folder (``tcp``: on a loopback TCP port instead). It starts at once;
    :meth:`wait_ready` returns the path (or the ``socket://`` URL)."""

    def __init__(self, workcell_path: str | Path, joints_controller=None, *, tcp: bool = False):
        # Resolved here, where the caller's folder is known: the child runs in the project's folder.
        workcell_path = Path(workcell_path).expanduser().resolve()
        self._folder = tempfile.TemporaryDirectory(prefix="videocal-sim-")
        folder = Path(self._folder.name)
        self.link_path = folder / "controller"
        self._stderr_path = folder / "stderr.txt"
        self.tcp = tcp
        where = ["--tcp", "0"] if tcp else ["--pty", "--link", str(self.link_path)]
        cmd = [sys.executable, "-m", "app.cli.main", "sim-controller", *where, "--workcell", str(workcell_path)]
        if joints_controller is not None:
            # one token: a first joint below zero would otherwise read as an option ("expected one argument")
            cmd += ["--joints=" + ",".join(f"{v:.4f}" for v in joints_controller)]
        with open(self._stderr_path, "w") as err:
            self.process = subprocess.Popen(
                cmd,
                stdout=subprocess.PIPE,
                stderr=err,
                stdin=subprocess.DEVNULL,
                text=True,
                cwd=str(_PROJECT),
                preexec_fn=_die_with_parent,
            )
        self.device: str | None = None

    def wait_ready(self) -> str:
        """The link path once the simulator serves; :class:`SiteError` with its own message if it failed."""
        if self.device is None:
            line = self.process.stdout.readline().strip()
            if not line:
                self.process.wait(timeout=5)
                why = self._stderr_path.read_text().strip().splitlines()
                raise SiteError(
                    "the controller simulator did not start: "
                    f"{why[-1] if why else f'exit code {self.process.returncode}'}"
                )
            self.device = line
        return self.device if self.tcp else str(self.link_path)

    @property
    def running(self) -> bool:
        return self.process.poll() is None

    def stop(self) -> None:
        """Terminate (then kill) the child and remove its folder; safe to call twice."""
        stop_child(self.process)
        self._folder.cleanup()
