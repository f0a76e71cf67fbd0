"""The simulated cell far away: videocal's own link to the controller simulator runs through a delay line (one-way
delay, jitter, loss; :mod:`videocal_sim.delay_line`), as the original's operator worked over a relay satellite.
The simulated camera follows the joints the link delivers, so its frames come as late as the link's samples, as a
gripper camera's would across the same link.
"""

from __future__ import annotations

import re

from videocal_sim.delay_line import DelayLine, LinkWeather
from videocal_sim.sim_process import SimulatorProcess
from videocal_sim.sim_site import SimulatedSite


class FarSimulatedSite(SimulatedSite):
    """A :class:`SimulatedSite` whose controller link crosses ``weather``."""

    def __init__(self, site: SimulatedSite, weather: LinkWeather, seed: int = 0):
        super().__init__(site.bed, camera_fps=site.camera_fps, camera_seed=site.camera_seed)
        self.weather = weather
        self.seed = seed
        self.line: DelayLine | None = None
        self.description = (
            f"simulated cell {self.bed.workcell.name}, {1000 * weather.one_way_s:.0f} ms away "
            f"(+-{100 * weather.jitter:.0f} %, {100 * weather.loss:g} % lost)"
        )

    def start_controller(self) -> str:
        if self.process is None:
            self.process = SimulatorProcess(
                self.bed.workcell.path, self.joint_map.to_controller(self.bed.joints_deg), tcp=True
            )
        if self.line is None:
            port = int(re.search(r":(\d+)$", self.process.wait_ready()).group(1))
            self.line = DelayLine(("127.0.0.1", 0), ("127.0.0.1", port), self.weather, seed=self.seed).start()
        return f"socket://127.0.0.1:{self.line.address[1]}"

    def close(self) -> None:
        if self.line is not None:
            self.line.close()
        super().close()
