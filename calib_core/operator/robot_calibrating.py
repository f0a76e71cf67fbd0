"""The operator core's robot calibration: plan the poses, run them (:class:`CalibrationRun`),
identify, apply the result to the cell's robot (and take it back), save it."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from calib_core.errors import OperatorError
from calib_core.robot.model import _to_mm, _to_se3


class RobotCalibrating:
    """Mixed into :class:`~calib_core.operator.core.OperatorCore`."""

    def plan_robot_calibration(self, spec, n: int = 40):
        """A :class:`~calib_core.robot_calibration.pose_planner.PosePlan` of ``n`` poses seeing the
        board where the cell puts it, each free of collisions, in an order whose every move from the
        current joints is free of collisions too."""
        from calib_core.operator.move_preview import joint_path
        from calib_core.robot_calibration.pose_planner import PosePlan, plan_poses

        world = self.collision_world()
        plan = plan_poses(self.robot, self.intrinsics, spec, self.board_placement(spec), n, start_deg=self.joints_deg, collisions=world, candidates=max(60, 3 * n))
        kept, q = [], np.asarray(self.joints_deg, dtype=float)
        for goal in plan.joints_deg:
            if not any(world.check(p) for p in joint_path(q, goal)):
                kept.append(goal)
                q = goal
        rejected = dict(plan.rejected)
        if len(kept) < len(plan.joints_deg):
            rejected["no collision-free path from the pose before"] = len(plan.joints_deg) - len(kept)
        return PosePlan(kept, plan.candidates, rejected, plan.log_det)

    def robot_calibration_run(self, spec, plan: list[np.ndarray]):
        """A :class:`~calib_core.operator.calibration_run.CalibrationRun` over ``plan`` (not started)."""
        from calib_core.operator.calibration_run import CalibrationRun

        return CalibrationRun(self, spec, plan)

    def calibrate_robot(self, capture, *, with_intrinsics: bool = False):
        """Identify the robot from a :class:`~calib_core.vision.capture.BoardCapture`'s views with
        joints; the robot as it is now (nominal, or calibrated before) is the start."""
        from calib_core.robot_calibration.identification import identify
        from calib_core.robot_calibration.observations import PoseView

        posed = [(v, q) for v, q in zip(capture.views, capture.joints_deg) if q is not None]
        if len(posed) < 6:
            raise OperatorError(f"{len(posed)} views with a robot pose, at least 6 needed (run the calibration plan)")
        corners = capture.spec.corners_mm()
        views = [PoseView(v.name, q, corners[v.ids], v.corners_px) for v, q in posed]
        result = identify(self.robot, self.intrinsics, views, with_intrinsics=with_intrinsics)
        self.record_event("robot_calibrated", views=len(views), rms_px=result.rms_px, identified=len(result.observability.identified))
        return result

    def apply_robot_calibration(self, result) -> None:
        """Use the calibrated joint and camera placements for everything from now on (the robot
        object stays the same, so every view follows); :meth:`revert_robot_calibration` takes it back."""
        if getattr(self, "_robot_before_calibration", None) is None:
            self._robot_before_calibration = ([_to_mm(p) for p in self.robot.model.jointPlacements], self.robot.frame_placement("camera"), self.robot.frame_placement("tcp"))
        for j in range(1, self.robot.model.njoints):
            self.robot.model.jointPlacements[j] = result.robot.model.jointPlacements[j]
        self.robot.set_frame_placement("camera", result.robot.frame_placement("camera"))
        self.robot.set_frame_placement("tcp", result.robot.frame_placement("tcp"))
        self.record_event("robot_calibration_applied", rms_px=result.rms_px)
        self.camera_model_changed.emit()
        self.scene_changed.emit()
        self.message.emit(f"calibrated robot in use ({len(result.observability.identified)} parameters, RMS {result.rms_px:.3f} px)")

    def revert_robot_calibration(self) -> None:
        before = getattr(self, "_robot_before_calibration", None)
        if before is None:
            raise OperatorError("no robot calibration is applied")
        placements, camera, tcp = before
        for j in range(1, self.robot.model.njoints):
            self.robot.model.jointPlacements[j] = _to_se3(placements[j])
        self.robot.set_frame_placement("camera", camera)
        self.robot.set_frame_placement("tcp", tcp)
        self._robot_before_calibration = None
        self.record_event("robot_calibration_reverted")
        self.camera_model_changed.emit()
        self.scene_changed.emit()
        self.message.emit("the robot's model as loaded is in use again")

    def save_robot_calibration(self, folder, result) -> tuple[Path, Path]:
        """``robot_calibration.yaml`` and the calibrated URDF into ``folder``."""
        from calib_core.robot_calibration.report import save_robot_calibration

        Path(folder).mkdir(parents=True, exist_ok=True)
        paths = save_robot_calibration(folder, result, result.nominal)
        self.message.emit(f"robot calibration saved to {paths[0]} and {paths[1]}")
        return paths
