"""What a workcell says about its robot: the description file, where its packages are, which
frames the program uses, which joints are driven, and how the controller numbers them.

No vendor file needs editing: every frame videocal needs (``base``, ``flange``, ``tcp``,
``camera``) is either the name of a frame the URDF has, or a new frame given by its parent
and a placement (:class:`NewFrame`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

FRAME_ROLES = ("base", "flange", "tcp", "camera")
"""The frames the program needs. ``base``: the frame poses are given and exported in (the
controller's base); ``flange``: where the camera mounting is measured from; ``tcp``: the tool
centre point, z along the approach; ``camera``: the camera, OpenCV axes (x right, y down, z out)."""

DEFAULT_FRAMES: dict[str, str | None] = {"base": None, "flange": "flange", "tcp": "tcp", "camera": "camera"}
"""``None`` for ``base`` means the URDF's root link."""


@dataclass(frozen=True)
class NewFrame:
    """A frame the URDF lacks: ``frame2parent`` (4, 4) mm relative to the URDF frame ``parent``."""

    parent: str
    frame2parent: np.ndarray


@dataclass(frozen=True)
class ControllerMap:
    """How the controller numbers and zeroes the driven joints.

    ``joints``: URDF joint names in the controller's axis order; ``zero_offsets``: per
    controller axis, controller value = URDF value + offset (deg for revolute, mm for prismatic).
    """

    joints: tuple[str, ...]
    zero_offsets: np.ndarray


@dataclass(frozen=True)
class RobotSpec:
    """The ``robot`` section of a workcell. ``home_joints``: the driven joints' home values
    (deg or mm, URDF order), ``None`` for all zero; ``held_joints``: joints not driven (gripper
    fingers), held at the value given (deg or mm); ``xacro_args``: a xacro description's arguments."""

    urdf: Path
    package_paths: tuple[Path, ...] = ()
    frames: dict[str, str | NewFrame | None] = field(default_factory=lambda: dict(DEFAULT_FRAMES))
    home_joints: np.ndarray | None = None
    held_joints: dict[str, float] = field(default_factory=dict)
    controller: ControllerMap | None = None
    xacro_args: dict[str, str] = field(default_factory=dict)
    """``$(arg name)`` values for a xacro description (``ur_type: ur10e``)."""
