"""The cell as modelled, as the 3-D panes (the virtual camera, the overview) draw it."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.operator.cell import Cell


class CellScene:
    """The modelled cell's read-outs the 3-D panes draw from: its components, the robot's links at given joints, the
    things put up in the cell for a while (a calibration board), the modelled camera and its intrinsics. Events (the
    cell's own): ``scene_changed()``, ``camera_model_changed()``."""

    def __init__(self, cell: Cell):
        self._cell = cell
        self.scene_changed = cell.scene_changed
        self.camera_model_changed = cell.camera_model_changed

    @property
    def intrinsics(self) -> Intrinsics:
        return self._cell.intrinsics

    @property
    def version(self) -> int:
        """Changes whenever what is drawn changes (a component placed, a board put up)."""
        return self._cell.scene_version

    @property
    def components(self) -> list:
        """The cell's components (SceneItems, their meshes mm in the base frame)."""
        return self._cell.workcell.components

    def component(self, name: str):
        return self._cell.workcell.component(name)

    def robot_items(self, joints_deg) -> list:
        """The robot's links as SceneItems at ``joints_deg`` (degrees)."""
        return self._cell.model_visuals().scene_items(joints_deg)

    def items(self, joints_deg) -> list:
        """Everything drawn with the robot at ``joints_deg``: components, the robot's links and what is put up."""
        return self.components + self.robot_items(joints_deg) + list(self._cell.extras)

    def model_cam2world(self, joints_deg) -> np.ndarray:
        """The modelled camera (4, 4) mm in the base frame at ``joints_deg`` (degrees)."""
        return self._cell.robot.fk(joints_deg, "camera")


class ModelledView:
    """What both 3-D panes draw: the modelled ``scene`` with the robot at the arm's ``joints_deg``, the ``target``
    highlighted, the ``pairs``' 3-D points. Events: ``pairs_changed``, ``target_changed`` and the scene's own."""

    def __init__(self, cell: Cell, session, arm):
        self._session, self._arm = session, arm
        self.scene = CellScene(cell)
        self.pairs = session.pairs
        self.pairs_changed = session.pairs.changed
        self.target_changed = session.target_changed

    @property
    def target(self) -> str | None:
        return self._session.target

    @property
    def joints_deg(self) -> np.ndarray:
        return self._arm.joints_deg
