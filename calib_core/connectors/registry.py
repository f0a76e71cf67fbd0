"""Opening a connector by its URL: the entry point registered under the URL's scheme.

``videocal.controllers``: ``name = "package.module:open"`` with ``open(url, context) -> ControllerConnector``;
``videocal.cameras``: ``name = "package.module:open"`` with ``open(spec, options) -> FrameSource``. The name
is the URL scheme (:mod:`calib_core.connectors.urls`). videocal registers its own connectors the same way
(``pyproject.toml``), so a user's package can add a scheme without touching videocal.
"""

from __future__ import annotations

from calib_core.connectors.controller import ControllerConnector, ControllerContext
from calib_core.connectors.urls import camera_scheme, controller_scheme
from calib_core.errors import VideocalError
from calib_core.plugins import load_plugin, plugin_names
from calib_core.connectors.frame import FrameSource

CONTROLLERS = "videocal.controllers"
CAMERAS = "videocal.cameras"


class ConnectorNotFoundError(VideocalError, LookupError):
    """No installed connector handles the URL's scheme; the message lists the ones that are."""


def _load(group: str, scheme: str, url: str, what: str):
    if any(ord(c) < 32 or ord(c) == 127 for c in url):
        # a NUL or a newline pasted into a URL: opened as it is, the connector's failure reads as a network fault
        raise ConnectorNotFoundError(
            f"the {what} address {url!r} holds a control character (a newline, a tab, a NUL): type it again"
        )
    if scheme not in plugin_names(group):
        installed = ", ".join(f"{name}://" for name in plugin_names(group)) or "none"
        raise ConnectorNotFoundError(f"no {what} connector for {url!r} (scheme {scheme!r}); installed: {installed}")
    return load_plugin(group, scheme)


def open_controller(url: str, context: ControllerContext) -> ControllerConnector:
    """The controller connector for ``url``, not started yet (call ``start()``)."""
    opener = _load(CONTROLLERS, controller_scheme(url), url, "controller")
    return opener(url, context)


def check_camera_spec(spec: str) -> None:
    """:class:`ConnectorNotFoundError` when no installed connector handles ``spec``'s scheme (nothing is opened)."""
    _load(CAMERAS, camera_scheme(spec), spec, "camera")


def open_camera(spec: str, options: dict | None = None) -> FrameSource:
    """The camera for ``spec``, open (its first :meth:`read` may still wait for the device)."""
    opener = _load(CAMERAS, camera_scheme(spec), spec, "camera")
    return opener(spec, options or {})
