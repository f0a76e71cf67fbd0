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
"""

from __future__ import annotations

import numpy as np

from calib_core.errors import OperatorError
from calib_core.operator.motion import Motion


class ToolMeasuring:
    """Mixed into :class:`~calib_core.operator.core.OperatorCore`."""

    @property
    def grasps(self) -> list:
        if not hasattr(self, "_grasps"):
            self._grasps = []
        return self._grasps

    def record_grasp(self):
        """A :class:`~calib_core.robot_calibration.camera_to_tool.Grasp` at the current task
        location from the joints the controller reports now, seen on the newest frame when its
        component's edges settle there (else through the robot and the fixture's survey, said so)."""
        from calib_core.robot_calibration.camera_to_tool import Grasp
        from calib_core.robot_calibration.grasp_view import GraspNotSeenError, see_grasp

        if self.task is None:
            raise OperatorError("choose a task location: the grasp puts the TCP on its fixture pin")
        if not self.link_up:
            raise OperatorError("the controller link is down: a grasp needs the joints the controller reports")
        if self.motion.motion in (Motion.MOVING, Motion.UNKNOWN):
            raise OperatorError(f"the robot is {self.motion.motion.value}: record the grasp once it stands with the gripper closed on the pin")
        q = np.array(self.joints_deg, dtype=float)
        seen, how = None, "no camera frame: taken through the robot and the fixture's survey"
        if self.observations.latest is not None:
            held = self.hold_frame()  # NotSettledError (nothing recorded) when the newest frame is of the robot moving
            q = np.asarray(held.stamp.joints_deg, dtype=float)
            item = self.workcell.component(self.task.component) if self.task.component else None
            try:
                seen = see_grasp(held.frame.image, self.intrinsics, self.robot, self.workcell, self.task, q,
                                 expected=self.modelled_view(q, item) if item is not None else None)
                how = f"seen on frame {held.stamp.frame_index} ({seen.edge_samples} edge samples of {seen.component})"
            except GraspNotSeenError as e:
                how = f"not seen ({e}): taken through the robot and the fixture's survey"
            self._release_unused_still()
        grasp = Grasp(f"{self.task.name} #{sum(g.name.startswith(self.task.name + ' #') for g in self.grasps) + 1}", q, self.task.tcp2base.copy(), seen)
        self.grasps.append(grasp)
        self.record_event("grasp_recorded", task=self.task.name, joints_deg=[float(v) for v in grasp.joints_deg], seen=seen is not None)
        self.message.emit(f"grasp recorded at {self.task.name} ({len(self.grasps)} in all): {how}")
        return grasp

    def clear_grasps(self) -> None:
        self.grasps.clear()
        self.message.emit("grasps cleared")

    def measure_tool(self):
        """The TCP in the camera frame from the recorded grasps
        (:class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool`), put into the robot's TCP
        frame; Revert takes it back."""
        from calib_core.robot_calibration.camera_to_tool import camera_to_tool, with_tool

        if not self.grasps:
            raise OperatorError("record a grasp first: close the gripper on a task location's pin in compliance, then Record grasp")
        from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM, pose_covariance

        calibration = getattr(self, "applied_robot_calibration", None)
        tool = camera_to_tool(self.robot, self.grasps, placement_sigma_mm=SURVEY_SIGMA_MM,
                              camera_covariance=(lambda q: pose_covariance(calibration, q)) if calibration is not None else None)
        self.measured_tool = tool
        placed = with_tool(self.robot, tool.tcp2cam)
        self.keep_robot_before_calibration()
        self.robot.set_frame_placement("tcp", placed.frame_placement("tcp"))
        self.record_event("tool_measured", grasps=len(self.grasps), spread_mm=tool.spread_mm)
        self.camera_model_changed.emit()
        self.scene_changed.emit()
        self.message.emit(f"TCP measured from {len(tool.per_grasp)} grasps, {tool.seen_grasps} seen (spread {tool.spread_mm:.3f} mm, {tool.spread_deg:.4f} deg)")
        return tool
