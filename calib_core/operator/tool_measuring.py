"""The operator core's camera to tool: grasps recorded at task locations, the TCP measured from them.

A camera sees camera poses, so views alone cannot say where the TCP is on the camera's joint. The
operator closes the gripper on the current task location's fixture pin with the controller in
compliance (on the teach pendant): the fingers centre on the pin, the joints follow, and the TCP is
where the fixture's survey says. :meth:`ToolMeasuring.record_grasp` keeps the joints the controller
reports then, and when the camera shows the fixture the gripper holds, measures the tool from that
frame (:mod:`calib_core.robot_calibration.grasp_view`: neither the fixture's survey nor the robot's
calibration enters); :meth:`ToolMeasuring.measure_tool` gives the TCP in the camera frame from all of them
through the robot as it is now (calibrated first, or the camera's errors go into the tool) and puts it
into the robot's TCP frame, undone by Revert like a robot calibration.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.tool``), given the cell, the task choice, the
arm, the frames (the one held for a grasp), Find points (the modelled view a grasp is checked against), the
robot calibration (which puts the tool in) and the log.
"""

from __future__ import annotations

import numpy as np

from calib_core.errors import OperatorError
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.motion import Motion
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.frame_holding import FrameHolding
from calib_core.operator.point_finding import PointFinding
from calib_core.operator.robot_calibrating import RobotCalibrating
from calib_core.operator.task_choice import TaskChoice


class ToolMeasuring:
    """``grasps``: the :class:`~calib_core.robot_calibration.camera_to_tool.Grasp` recorded so far."""

    def __init__(
        self,
        cell: Cell,
        tasks: TaskChoice,
        arm: Arm,
        frames: FrameHolding,
        finder: PointFinding,
        robot_calibration: RobotCalibrating,
        log: OperatorLog,
    ):
        self._cell, self._tasks, self._arm, self._frames, self._finder, self._robot_calibration, self._log = (
            cell,
            tasks,
            arm,
            frames,
            finder,
            robot_calibration,
            log,
        )
        self.grasps: list = []

    @property
    def task(self):
        return self._tasks.task

    def record_grasp(self):
        """A :class:`~calib_core.robot_calibration.camera_to_tool.Grasp` at the current task
        location from the joints the controller reports now, seen on the newest frame when its
        component's edges settle there (else through the robot and the fixture's survey, said so)."""
        from calib_core.robot_calibration.camera_to_tool import Grasp
        from calib_core.robot_calibration.grasp_view import GraspNotSeenError, see_grasp

        if self.task is None:
            raise OperatorError("choose a task location: the grasp puts the TCP on its fixture pin")
        if not self._arm.link_up:
            raise OperatorError("the controller link is down: a grasp needs the joints the controller reports")
        if self._arm.state.motion in (Motion.MOVING, Motion.UNKNOWN):
            raise OperatorError(
                f"the robot is {self._arm.state.motion.value}: record the grasp once it stands with the gripper closed "
                "on the pin"
            )
        q = np.array(self._arm.joints_deg, dtype=float)
        seen, how = None, "no camera frame: taken through the robot and the fixture's survey"
        if self._frames.latest is not None:
            held = (
                self._frames.hold_frame()
            )  # NotSettledError (nothing recorded) when the newest frame is of the robot moving
            q = np.asarray(held.stamp.joints_deg, dtype=float)
            workcell = self._cell.workcell
            item = workcell.component(self.task.component) if self.task.component else None
            try:
                seen = see_grasp(
                    held.frame.image,
                    self._cell.intrinsics,
                    self._cell.robot,
                    workcell,
                    self.task,
                    q,
                    expected=self._finder.modelled_view(q, item) if item is not None else None,
                )
                how = f"seen on frame {held.stamp.frame_index} ({seen.edge_samples} edge samples of {seen.component})"
            except GraspNotSeenError as e:
                how = f"not seen ({e}): taken through the robot and the fixture's survey"
            self._frames.release_unused_still()
        grasp = Grasp(
            f"{self.task.name} #{sum(g.name.startswith(self.task.name + ' #') for g in self.grasps) + 1}",
            q,
            self.task.tcp2base.copy(),
            seen,
        )
        self.grasps.append(grasp)
        self._log.record(
            "grasp_recorded",
            task=self.task.name,
            joints_deg=[float(v) for v in grasp.joints_deg],
            seen=seen is not None,
        )
        self._log.say(f"grasp recorded at {self.task.name} ({len(self.grasps)} in all): {how}")
        return grasp

    def clear_grasps(self) -> None:
        self.grasps.clear()
        self._log.say("grasps cleared")

    def measure_tool(self):
        """The TCP in the camera frame from the recorded grasps
        (:class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool`), put into the robot's TCP
        frame; Revert takes it back."""
        from calib_core.robot_calibration.camera_to_tool import camera_to_tool

        if not self.grasps:
            raise OperatorError(
                "record a grasp first: close the gripper on a task location's pin in compliance, then Record grasp"
            )
        from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM

        calibration = self._robot_calibration.applied_robot_calibration
        tool = camera_to_tool(
            self._cell.robot,
            self.grasps,
            placement_sigma_mm=SURVEY_SIGMA_MM,
            camera_covariance=(lambda q: calibration.pose_covariance(q)) if calibration is not None else None,
        )
        self._robot_calibration.use_tool(tool)
        self._log.record("tool_measured", grasps=len(self.grasps), spread_mm=tool.spread_mm)
        self._log.say(
            f"TCP measured from {len(tool.per_grasp)} grasps, {tool.seen_grasps} seen (spread {tool.spread_mm:.3f} mm, "
            f"{tool.spread_deg:.4f} deg)"
        )
        return tool
