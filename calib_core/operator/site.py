"""Where the devices come from. A *site* gives the operator core a controller link URL and a
camera; the core never knows which kind of site it has.

:class:`RealSite` is a controller URL and a camera spec. The simulated site
(:class:`videocal_sim.sim_site.SimulatedSite`) starts a controller simulator and a
simulated camera for the cell the operator opened, and is the only code that knows the truth.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from calib_core.scene import SceneItem
from calib_core.video.frame import FrameSource


class Site(Protocol):
    """What the core asks of a site."""

    description: str

    def start_controller(self) -> str:
        """Make the controller reachable; returns the link URL (a port, a pty, ``socket://``)."""

    def camera_factory(self) -> Callable[[], FrameSource]:
        """A function that opens the camera (called on the camera's worker thread)."""

    def attach(self, link) -> None:
        """Called once the link is open (a simulated site follows the controller's joints)."""

    def put_up(self, items: list[SceneItem]) -> None:
        """Things the operator put into the cell for a while (a calibration board)."""

    def close(self) -> None:
        """Stop what the site started; safe to call twice."""


def open_camera_spec(spec: str) -> FrameSource:
    """A camera from a command-line spec: an OpenCV device index, a video file or stream URL, or
    a folder of images (played in a loop)."""
    from calib_core.video.folder_source import ImageFolderSource
    from calib_core.video.opencv_source import OpenCVSource

    if Path(spec).is_dir():
        return ImageFolderSource(spec, loop=True)
    return OpenCVSource(int(spec) if spec.isdigit() else spec)


class RealSite:
    """A real controller at ``controller_url`` and a real camera (``camera`` spec, see
    :func:`open_camera_spec`; ``None`` for no camera)."""

    def __init__(self, controller_url: str, camera: str | None = None):
        self.controller_url = controller_url
        self.camera = camera
        self.description = f"controller {controller_url}" + (f", camera {camera}" if camera else "")

    def start_controller(self) -> str:
        return self.controller_url

    def camera_factory(self) -> Callable[[], FrameSource] | None:
        if self.camera is None:
            return None
        spec = self.camera
        return lambda: open_camera_spec(spec)

    def attach(self, link) -> None:
        pass

    def put_up(self, items: list[SceneItem]) -> None:
        pass  # the operator puts the real board up; the core shows it in the CAD views

    def close(self) -> None:
        pass
