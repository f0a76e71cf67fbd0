"""The simulated cell with a Universal Robots controller: the robot is ``videocal sim-ur`` in a child process (RTDE,
URScript, dashboard on UR's ports, on a loopback address of its own), reached only through the ``ur-rtde://``
connector (``ur_rtde``'s RTDE client, URScript ``movej``), as a real UR's would be. The camera stays the simulated
site's: it renders from where the controller says the robot is.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

from videocal_sim.sim_process import _PROJECT, SiteError, _die_with_parent, stop_child
from videocal_sim.sim_site import SimulatedSite


def free_loopback_host() -> str:
    """A loopback address whose RTDE port (30004) nobody serves: several simulated URs on one machine (tests in
    parallel) each need their own, the ports being the controller's fixed ones."""
    for k in range(1, 250):
        host = f"127.{60 + os.getpid() % 100}.{k}.1"
        with socket.socket() as probe:
            try:
                probe.bind((host, 30004))
                return host
            except OSError:
                continue
    raise SiteError("no free loopback address for a simulated UR controller (127.x.y.1:30004 all taken)")


class URSimulatedSite(SimulatedSite):
    """A :class:`SimulatedSite` whose robot is a simulated UR controller (the cell's robot needs 6 revolute joints)."""

    def __init__(self, site: SimulatedSite):
        super().__init__(site.bed, camera_fps=site.camera_fps, camera_seed=site.camera_seed)
        self.description = f"simulated cell {self.bed.workcell.name} on a simulated Universal Robots controller (RTDE)"
        self.host: str | None = None
        self.ur: subprocess.Popen | None = None
        self._folder = tempfile.TemporaryDirectory(prefix="videocal-sim-ur-")

    def start_controller(self) -> str:
        if self.ur is None:
            self.host = free_loopback_host()
            stderr_path = Path(self._folder.name) / "stderr.txt"
            cmd = [
                sys.executable,
                "-m",
                "app.cli.main",
                "sim-ur",
                "--host",
                self.host,
                "--workcell",
                str(Path(self.bed.workcell.path).resolve()),
                "--joints=" + ",".join(f"{v:.6f}" for v in self.bed.joints_deg),  # one token: may start with "-"
            ]
            with open(stderr_path, "w") as err:
                self.ur = subprocess.Popen(
                    cmd,
                    stdin=subprocess.PIPE,
                    stdout=subprocess.PIPE,
                    stderr=err,
                    text=True,
                    cwd=str(_PROJECT),
                    preexec_fn=_die_with_parent,
                )
            if self.ur.stdout.readline().strip() != "ready":
                self.ur.wait(timeout=5)
                why = stderr_path.read_text().strip().splitlines()
                raise SiteError(
                    "the simulated UR controller did not start: "
                    f"{why[-1] if why else f'exit code {self.ur.returncode}'}"
                )
        return f"ur-rtde://{self.host}"

    def close(self) -> None:
        if self.ur is not None:
            if self.ur.stdin is not None:
                self.ur.stdin.close()
            stop_child(self.ur)
            self.ur = None
        self._folder.cleanup()
        super().close()
