"""The workcell overview's model: the cell as modelled, the model's and the measured camera, a move's preview."""

from __future__ import annotations

from calib_core.calibration.session import CalibrationSession
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.moves import Moves
from calib_core.operator.panes.cell_scene import ModelledView


class OverviewPaneModel(ModelledView):
    """What the overview shows and does: beside what both 3-D panes draw (:class:`ModelledView`), the measured camera
    (the result's ``estimate``), a move's preview and the robot's motion (``robot_state``); its one action stops the
    robot. Events it redraws on beside the view's: ``result_changed``, ``move_previewed``, ``motion_changed``,
    ``prompts_withdrawn``."""

    def __init__(self, cell: Cell, session: CalibrationSession, arm: Arm, moves: Moves):
        super().__init__(cell, session, arm)
        self._moves = moves
        self.result_changed = session.result.changed
        self.move_previewed = arm.move_previewed
        self.motion_changed = arm.motion_changed
        self.prompts_withdrawn = arm.prompts_withdrawn

    @property
    def estimate(self):
        """The last solve's estimate (its ``cam2world_measured``), or ``None``."""
        return self._session.result.estimate

    @property
    def robot_state(self):
        """The robot's motion state now (``motion``, ``what``, ``text``)."""
        return self._arm.state

    def stop_robot(self) -> None:
        self._moves.stop_robot()
