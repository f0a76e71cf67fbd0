"""Where the devices come from. A *site* gives the operator core a controller link URL and a
camera; the core never knows which kind of site it has.

:class:`RealSite` is a controller URL and a camera spec. The simulated site
(:class:`videocal_sim.sim_site.SimulatedSite`) starts a controller simulator and a
simulated camera for the cell the operator opened, and is the only code that knows the truth.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from calib_core.connectors.registry import open_camera
from calib_core.scene import SceneItem
from calib_core.connectors.frame import FrameSource


class Site(Protocol):
    """What the core asks of a site."""

    description: str

    def start_controller(self) -> str | None:
        """Make the controller reachable; returns its connector URL (a port, ``socket://``, ``ros2://``...),
        or ``None`` when the site has no controller."""

    def camera_factory(self) -> Callable[[], FrameSource]:
        """A function that opens the camera (called on the camera's worker thread)."""

    def attach(self, link) -> None:
        """Called once the link is open (a simulated site follows the controller's joints)."""

    def put_up(self, items: list[SceneItem]) -> None:
        """Things the operator put into the cell for a while (a calibration board)."""

    def close(self) -> None:
        """Stop what the site started; safe to call twice."""


class RealSite:
    """A real controller at ``controller_url`` and a real camera ``camera``, each through the connector
    registered for its URL's scheme (:mod:`calib_core.connectors.registry`); either may be ``None`` (a
    camera alone, for picking and solving without moving; a controller alone). ``controller_options`` and
    ``camera_options``: the connectors' options from the workcell's ``site:`` section."""

    def __init__(
        self,
        controller_url: str | None,
        camera: str | None = None,
        *,
        controller_options: dict | None = None,
        camera_options: dict | None = None,
    ):
        self.controller_url = controller_url
        self.camera = camera
        self.controller_options = controller_options
        self.camera_options = camera_options
        parts = ([f"controller {controller_url}"] if controller_url else ["no controller"]) + (
            [f"camera {camera}"] if camera else []
        )
        self.description = ", ".join(parts)

    def start_controller(self) -> str | None:
        return self.controller_url

    def camera_factory(self) -> Callable[[], FrameSource] | None:
        if self.camera is None:
            return None
        spec, options = self.camera, self.camera_options
        return lambda: open_camera(spec, options)

    def attach(self, link) -> None:
        pass

    def put_up(self, items: list[SceneItem]) -> None:
        pass  # the operator puts the real board up; the core shows it in the CAD views

    def close(self) -> None:
        pass
