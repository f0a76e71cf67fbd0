"""The robot panel's model: the robot's calibration (plan, run, identify, apply, revert, save), the board it is
calibrated against in the cell, the camera-to-tool measurement beside it."""

from __future__ import annotations

from calib_core.operator.camera_calibrating import CameraCalibrating
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.robot_calibrating import RobotCalibrating
from calib_core.operator.tool_measuring import ToolMeasuring


class RobotPaneModel:
    """What the robot panel does: the robot calibration's steps (each the core's
    :class:`~calib_core.operator.robot_calibrating.RobotCalibrating`), the board put up in the simulated cell, a line
    in the log; ``tool``: the camera-to-tool measurement the panel's tool group shows (its own model)."""

    def __init__(self, calibrating: RobotCalibrating, vision: CameraCalibrating, tool: ToolMeasuring, log: OperatorLog):
        self._calibrating, self._vision, self._log = calibrating, vision, log
        self.tool = tool

    @property
    def can_revert(self) -> bool:
        return self._calibrating.can_revert

    def plan(self, spec, poses: int):
        """The board poses and the views of surveyed components to drive through (a plan with ``joints_deg``)."""
        return self._calibrating.plan_robot_calibration(spec, poses)

    def run(self, spec, joints_deg, cell_views):
        """A run through the planned poses (a CalibrationRun: ``start()``, ``progress``, ``finished``)."""
        return self._calibrating.robot_calibration_run(spec, joints_deg, cell_views)

    def identify(self, capture, *, cell_frames=(), with_intrinsics: bool = False, progress=None):
        """The robot's parameters from a run's views (the identification's result)."""
        return self._calibrating.calibrate_robot(
            capture, cell_frames=cell_frames, with_intrinsics=with_intrinsics, progress=progress
        )

    def apply(self, result) -> None:
        self._calibrating.apply_robot_calibration(result)

    def revert(self) -> None:
        self._calibrating.revert_robot_calibration()

    def save(self, folder, result, tool=None):
        return self._calibrating.save_robot_calibration(folder, result, tool)

    def show_board(self, spec, on: bool):
        """Put the board up in the simulated cell (or take it down)."""
        return self._vision.show_board(spec, on)

    def say(self, text: str) -> None:
        self._log.say(text)
