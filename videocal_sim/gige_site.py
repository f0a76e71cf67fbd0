"""The simulated cell with its camera served as a GigE Vision camera (Aravis's fake GigE Vision camera on the
loopback interface): the window reads it through the ``aravis://`` connector, over GVCP/GVSP, as a real
GenICam camera. The controller stays the simulated site's."""

from __future__ import annotations

from collections.abc import Callable

from videocal_sim.sim_site import SimulatedSite


class GigESimulatedSite(SimulatedSite):
    def __init__(self, site: SimulatedSite):
        super().__init__(site.bed, process=site.process, camera_fps=site.camera_fps, camera_seed=site.camera_seed)
        self.description = f"simulated cell {self.bed.workcell.name}, camera over GigE Vision (Aravis)"
        self.server = None
        self._source = None

    def camera_factory(self, fps: float | None = None) -> Callable:
        from calib_core.connectors.registry import open_camera
        from videocal_sim.gige_camera import SimulatedGigECamera

        if self.server is None:
            # Rendered when the fake camera exposes (stamps) each frame: where the robot stands then.
            self._source = self.bed.camera(fps=fps or self.camera_fps, seed=self.camera_seed, live=True)
            self.server = SimulatedGigECamera(lambda: self._source.read().image)
        i = self.bed.intrinsics
        spec = f"aravis://127.0.0.1?pixel_format=RGB8&width={i.width}&height={i.height}"
        return lambda: open_camera(spec)

    def close(self) -> None:
        if self.server is not None:
            self.server.close()
            self._source.close()
        super().close()
