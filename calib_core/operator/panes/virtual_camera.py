"""The virtual camera pane's model: the cell as modelled, seen by the modelled camera, and the 3-D picks."""

from __future__ import annotations

from calib_core.calibration.session import CalibrationSession
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.panes.cell_scene import ModelledView
from calib_core.operator.picking import Picking


class VirtualPaneModel(ModelledView):
    """What the virtual camera pane shows and does: the modelled ``scene`` seen by the modelled camera at the arm's
    joints, the target and its features, the pairs' 3-D points (:class:`ModelledView`); a click picks a point on
    the target's model."""

    def __init__(self, cell: Cell, session: CalibrationSession, arm: Arm, picking: Picking):
        super().__init__(cell, session, arm)
        self._picking = picking

    def pick_model_point(self, component: str, feature: str | None, point_world_mm) -> int:
        """The first half of a pair: a point (3,) mm in the base frame on ``component``; its pair's number."""
        return self._picking.pick_model_point(component, feature, point_world_mm)
