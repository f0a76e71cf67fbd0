"""A loaded workcell: what the renderer, the window and the calibration use."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from calib_core.frames import apply, concat, make_transform
from calib_core.robot.model import RobotModel, load_robot
from calib_core.robot.spec import RobotSpec
from calib_core.scene import SceneItem
from calib_core.errors import UnknownNameError
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM, SafetyLimits


@dataclass(frozen=True)
class TaskLocation:
    """A named task location. ``tcp2base`` (4, 4) mm: where the tool centre point must be;
    ``approach_mm``: how far back along the tool's approach axis (its z) the robot stops
    first, where the camera sees the component; ``component``: the object it works on;
    ``tolerance_mm``: how close the task needs the tool (a calibration whose 1-sigma is above it
    cannot vouch for the task)."""

    name: str
    tcp2base: np.ndarray
    approach_mm: float = 0.0
    component: str | None = None
    tolerance_mm: float = DEFAULT_TOLERANCE_MM

    @property
    def approach2base(self) -> np.ndarray:
        """The TCP pose (4, 4) mm at the approach: ``approach_mm`` back along the tool z axis."""
        return concat(make_transform(np.eye(3), [0.0, 0.0, -self.approach_mm]), self.tcp2base)


@dataclass
class Workcell:
    """Components (as :class:`SceneItem`, placed in the robot's ``base`` frame), task locations,
    the robot (``robot_spec``: its description, frames and joints) and the camera file the cell
    uses; ``home_joints_deg`` (n,) deg/mm for the driven joints."""

    name: str
    path: Path
    components: list[SceneItem]
    task_locations: dict[str, TaskLocation]
    robot_spec: RobotSpec
    intrinsics_path: Path | None
    home_joints_deg: np.ndarray
    meta: dict = field(default_factory=dict)
    safety: SafetyLimits = field(default_factory=SafetyLimits)

    @property
    def site(self):
        """The cell's ``site:`` section (:class:`~calib_core.workcell.site_section.SiteSection`), or None."""
        return self.meta.get("site")

    @property
    def robot_urdf(self) -> Path:
        return self.robot_spec.urdf

    def load_robot(self) -> RobotModel:
        """A fresh model of the cell's robot (its frames, held joints and base as the file says)."""
        return load_robot(self.robot_spec)

    def component(self, name: str) -> SceneItem:
        """The component called ``name``; ``KeyError`` names the known ones."""
        for item in self.components:
            if item.name == name:
                return item
        raise UnknownNameError(
            f"the workcell has no component '{name}'; components: {', '.join(c.name for c in self.components)}"
        )

    def task(self, name: str) -> TaskLocation:
        """The task location called ``name``; ``KeyError`` names the known ones."""
        if name not in self.task_locations:
            raise UnknownNameError(
                f"the workcell has no task location '{name}'; task locations: {', '.join(self.task_locations)}"
            )
        return self.task_locations[name]

    def feature_in_base(self, component: str, feature: str) -> np.ndarray:
        """A named feature point of a component in the robot base frame (3,), mm."""
        item = self.component(component)
        if feature not in item.features:
            raise UnknownNameError(
                f"component '{component}' has no feature '{feature}'; features: {', '.join(item.features)}"
            )
        return apply(item.item2world, item.features[feature])

    @property
    def triangle_count(self) -> int:
        return sum(len(c.mesh.faces) for c in self.components)
