"""The workcell's ``site:`` section: which controller and camera the real cell has.

.. code-block:: yaml

    site:
      controller: ros2:///joint_states        # a connector URL (see docs/connectors.md)
      controller_options: {trajectory_controller: joint_trajectory_controller}
      camera: aravis://Basler-12345           # a camera spec; a relative path is the workcell's folder
      camera_options: {exposure_us: 8000}
      camera_frame: camera_color_optical_frame   # the camera driver's optical frame (default
      videocal_camera_optical_frame)
      camera_parent_frame: tool0              # the link the camera hangs from (default: the robot's flange link)

The command line's ``--port`` and ``--camera`` take precedence; ``--site sim`` ignores the section.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from calib_core.connectors.urls import url_scheme

SITE_KEYS = {"controller", "controller_options", "camera", "camera_options", "camera_frame", "camera_parent_frame"}
_FRAME_NAME = re.compile(r"[A-Za-z_/][A-Za-z0-9_/]*")
"""A tf frame name: letters, digits, underscores and slashes (ROS names), not starting with a digit."""


@dataclass(frozen=True)
class SiteSection:
    """``controller``: a controller connector URL or None; ``camera``: a camera spec or None (a path made
    absolute against the workcell's folder); the connectors' ``*_options``."""

    controller: str | None = None
    camera: str | None = None
    controller_options: dict = field(default_factory=dict)
    camera_options: dict = field(default_factory=dict)
    camera_frame: str | None = None
    """The camera's tf frame in what ROS is given (:mod:`calib_core.ros2.frame_names`); None: videocal's default."""
    camera_parent_frame: str | None = None
    """The tf frame the camera hangs from; None: the robot's flange link."""


def read_site_section(reader, raw, folder: Path) -> SiteSection:
    """The ``site`` mapping checked (``reader`` names the file and field of a fault)."""
    raw = reader.mapping(raw, "site", SITE_KEYS, set())
    values = {}
    for key in ("controller", "camera"):
        value = raw.get(key)
        if value is not None and (not isinstance(value, str) or not value.strip() or len(value) > 1000):
            raise reader.fail(f"site.{key}", f"must be a URL or path (a non-empty string), got {value!r}")
        if value is not None and any(ord(c) < 32 or ord(c) == 127 for c in value):
            raise reader.fail(f"site.{key}", f"holds a control character (a newline, a tab, a NUL): {value!r}")
        values[key] = value
    camera = values["camera"]
    if camera is not None and url_scheme(camera) is None and not camera.strip().isdigit():
        camera = str((folder / camera).resolve())
    options = {}
    for key in ("controller_options", "camera_options"):
        value = raw.get(key) or {}
        if not isinstance(value, dict):
            raise reader.fail(f"site.{key}", f"must be a mapping of option names to values, got {type(value).__name__}")
        for name, v in value.items():
            if not isinstance(name, str) or not (v is None or isinstance(v, (str, int, float, bool))):
                raise reader.fail(f"site.{key}.{name}", f"must be a plain value (text, number, true/false), got {v!r}")
        options[key] = dict(value)
    names = {}
    for key in ("camera_frame", "camera_parent_frame"):
        value = raw.get(key)
        if value is not None and (not isinstance(value, str) or not _FRAME_NAME.fullmatch(value) or len(value) > 200):
            raise reader.fail(
                f"site.{key}",
                f"must be a tf frame name (letters, digits, _ and /, not starting with a digit), got {value!r}",
            )
        names[key] = value
    return SiteSection(
        values["controller"],
        camera,
        options["controller_options"],
        options["camera_options"],
        names["camera_frame"],
        names["camera_parent_frame"],
    )
