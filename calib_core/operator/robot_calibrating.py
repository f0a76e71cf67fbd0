"""The operator core's robot calibration: plan the poses, run them (:class:`CalibrationRun`),
identify, apply the result to the cell's robot (and take it back), save it. The one owner of the changes
made to the cell's robot in place: a calibration applied, a measured tool (:mod:`~calib_core.operator.tool_measuring`
measures it, this puts it in), and Revert, which takes both back.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.robot_calibration``), given the cell, the
session (the look to fuse), the arm (where the robot stands, the moves of a run) and the log."""

from __future__ import annotations

import dataclasses

from pathlib import Path

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.errors import OperatorError
from calib_core.frames import concat, invert
from calib_core.operator.arm import Arm
from calib_core.operator.calibration_run import VIA
from calib_core.operator.cell import Cell
from calib_core.operator.operator_log import OperatorLog
from calib_core.robot.model import _to_mm, _to_se3


class RobotCalibrating:
    """``applied_robot_calibration`` (the result in use, or ``None``), ``measured_tool`` (a
    :class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool` in use, or ``None``)."""

    def __init__(self, cell: Cell, session: CalibrationSession, arm: Arm, log: OperatorLog):
        self._cell, self._session, self._arm, self._log = cell, session, arm, log
        self.applied_robot_calibration = None
        self.measured_tool = None
        self._robot_before_calibration = None
        self._intrinsics_before_calibration = None

    def plan_robot_calibration(self, spec, n: int = 40, *, cell_views_per_target: int = 3):
        """A :class:`~calib_core.robot_calibration.pose_planner.PosePlan` of ``n`` poses seeing the
        board where the cell puts it, then ``cell_views_per_target`` poses seeing each surveyed
        component the tie to the cell uses; each free of collisions, in an order whose every move
        from the current joints is free of collisions too."""
        from calib_core.operator.move_preview import joint_path
        from calib_core.robot_calibration.cell_views import cell_view_joints
        from calib_core.robot_calibration.pose_planner import PosePlan, plan_poses

        from calib_core.vision.board_placement import board_in_cell

        world = self._cell.collision_world()
        start = np.asarray(self._arm.joints_deg, dtype=float)
        plan = plan_poses(
            self._cell.robot,
            self._cell.intrinsics,
            spec,
            board_in_cell(spec, self._cell.workcell, self._cell.robot),
            n,
            start_deg=start,
            collisions=world,
            candidates=max(60, 3 * n),
        )
        kept, q = [], start
        for goal in plan.joints_deg:
            if not any(world.check(p) for p in joint_path(q, goal)):
                kept.append(goal)
                q = goal
        rejected = dict(plan.rejected)
        if len(kept) < len(plan.joints_deg):
            rejected["no collision-free path from the pose before"] = len(plan.joints_deg) - len(kept)
        cell, home = [], np.asarray(self._cell.home_joints, dtype=float)

        def free(a, b):
            return not any(world.check(p) for p in joint_path(a, b))

        for component, goal in (
            cell_view_joints(
                self._cell.robot, self._cell.workcell, self._cell.intrinsics, cell_views_per_target, collisions=world
            )
            if cell_views_per_target
            else []
        ):
            if free(q, goal):
                cell.append((component, goal))
            elif free(q, home) and free(home, goal):  # round the cell's obstacles through home
                cell += [(VIA, home), (component, goal)]
            else:
                rejected["a component's view with no collision-free path"] = (
                    rejected.get("a component's view with no collision-free path", 0) + 1
                )
                continue
            q = goal
        return PosePlan(kept, plan.candidates, rejected, plan.log_det, cell)

    def robot_calibration_run(self, spec, plan: list[np.ndarray], cell_views=()):
        """A :class:`~calib_core.operator.calibration_run.CalibrationRun` over ``plan`` then the
        components' ``cell_views`` ((component, joints deg)), not started."""
        from calib_core.operator.calibration_run import CalibrationRun

        return CalibrationRun(self._arm, self._log, spec, plan, cell_views)

    def calibrate_robot(self, capture, *, cell_frames=(), with_intrinsics: bool = False, progress=None):
        """Identify the robot from a :class:`~calib_core.vision.capture.BoardCapture`'s views with
        joints and the run's ``cell_frames``
        (:class:`~calib_core.robot_calibration.identify_robot.CellFrame`), through the one driver
        (:func:`~calib_core.robot_calibration.identify_robot.identify_robot`); the robot as it is now
        (nominal, or calibrated before) is the start. A component not located is named in the
        result's warnings. ``progress(done, total, text)``."""
        from calib_core.robot_calibration.identify_robot import identify_robot
        from calib_core.robot_calibration.observations import PoseView

        posed = [(v, q) for v, q in zip(capture.views, capture.joints_deg) if q is not None]
        if len(posed) < 6:
            raise OperatorError(f"{len(posed)} views with a robot pose, at least 6 needed (run the calibration plan)")
        corners = capture.spec.corners_mm()
        views = [PoseView(v.name, q, corners[v.ids], v.corners_px) for v, q in posed]
        done = identify_robot(
            self._cell.robot,
            self._cell.intrinsics,
            self._cell.workcell,
            views,
            cell_frames,
            visuals=self._cell.model_visuals(),
            extras=self._cell.extras,
            with_intrinsics=with_intrinsics,
            progress=progress,
        )
        result = done.result
        self._log.record(
            "robot_calibrated",
            views=done.board_views,
            component_views=done.cell_views,
            rms_px=result.rms_px,
            identified=len(result.observability.identified),
        )
        return result

    def apply_robot_calibration(self, result) -> None:
        """Use the calibrated joint and camera placements (and the intrinsics, when the identification
        refined them) for everything from now on (the robot object stays the same, so every view
        follows); :meth:`revert_robot_calibration` takes it back."""
        self.keep_robot_before_calibration()
        self.applied_robot_calibration = result
        for j in range(1, self._cell.robot.model.njoints):
            self._cell.robot.model.jointPlacements[j] = result.robot.model.jointPlacements[j]
        self._cell.robot.set_frame_placement("camera", result.robot.frame_placement("camera"))
        self._cell.robot.set_frame_placement("tcp", result.robot.frame_placement("tcp"))
        if result.intrinsics != self._cell.intrinsics:  # refined with the robot: the camera as the same fit saw it
            if self._intrinsics_before_calibration is None:
                self._intrinsics_before_calibration = self._cell.intrinsics
            self._cell.use_intrinsics(result.intrinsics)
        self._log.record("robot_calibration_applied", rms_px=result.rms_px)
        self._cell.robot_edited()
        self._log.say(
            f"calibrated robot in use ({len(result.observability.identified)} parameters, RMS {result.rms_px:.3f} px)"
        )

    def look_fused_with_robot(self, look):
        """The look (an :class:`~calib_core.calibration.end_effector.EndEffectorEstimate` at its
        solve's joints) weighed against the calibrated robot in use
        (:func:`~calib_core.calibration.look_fusion.fuse_look`: the model's TCP covariance there, the
        component placed to the survey's sigma); ``None`` without an applied robot calibration or a
        look without covariance."""
        result = self.applied_robot_calibration
        context = self._session.result.context
        if result is None or look is None or look.covariance is None or context is None or context.joints_deg is None:
            return None
        from calib_core.calibration.look_fusion import fuse_look, tcp_covariance_from_camera
        from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM

        q = context.joints_deg
        cam2base = self._cell.robot.fk(q, "camera")
        model = tcp_covariance_from_camera(
            result.pose_covariance(q), cam2base, concat(self._cell.robot.fk(q, "tcp"), invert(cam2base))
        )
        fused = fuse_look(look, model, placement_sigma_mm=SURVEY_SIGMA_MM)
        tool = self.measured_tool
        tool_covariance = tool.covariance_in_base(cam2base) if tool is not None else None
        if tool_covariance is None:
            return fused
        # look and model share the tool's error (the grasped fixtures' survey): added after the fusion
        return dataclasses.replace(fused, covariance=fused.covariance + tool_covariance)

    def keep_robot_before_calibration(self) -> None:
        """The robot's placements as loaded, kept once for :meth:`revert_robot_calibration`."""
        if self._robot_before_calibration is None:
            self._robot_before_calibration = (
                [_to_mm(p) for p in self._cell.robot.model.jointPlacements],
                self._cell.robot.frame_placement("camera"),
                self._cell.robot.frame_placement("tcp"),
            )

    @property
    def can_revert(self) -> bool:
        """Whether the robot in use differs from the one loaded (a calibration applied, a tool measured)."""
        return self._robot_before_calibration is not None

    def revert_robot_calibration(self) -> None:
        before = self._robot_before_calibration
        if before is None:
            raise OperatorError("no robot calibration is applied")
        placements, camera, tcp = before
        for j in range(1, self._cell.robot.model.njoints):
            self._cell.robot.model.jointPlacements[j] = _to_se3(placements[j])
        self._cell.robot.set_frame_placement("camera", camera)
        self._cell.robot.set_frame_placement("tcp", tcp)
        self._robot_before_calibration = None
        self.applied_robot_calibration = None
        self.measured_tool = None
        if self._intrinsics_before_calibration is not None:
            self._cell.use_intrinsics(self._intrinsics_before_calibration)
            self._intrinsics_before_calibration = None
        self._log.record("robot_calibration_reverted")
        self._cell.robot_edited()
        self._log.say("the robot's model as loaded is in use again")

    def use_tool(self, tool) -> None:
        """Put a measured tool (:class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool`) into the
        robot's TCP frame; Revert takes it back."""
        from calib_core.robot_calibration.camera_to_tool import with_tool

        self.keep_robot_before_calibration()
        self.measured_tool = tool
        self._cell.robot.set_frame_placement("tcp", with_tool(self._cell.robot, tool.tcp2cam).frame_placement("tcp"))
        self._cell.robot_edited()

    def save_robot_calibration(self, folder, result, tool=None) -> tuple[Path, Path]:
        """``robot_calibration.yaml`` and the calibrated URDF into ``folder``; with ``tool`` (from
        :meth:`measure_tool`) the URDF's TCP joint carries it and the YAML says it was measured."""
        from calib_core.robot_calibration.camera_to_tool import with_tool
        from calib_core.robot_calibration.report import save_robot_calibration

        Path(folder).mkdir(parents=True, exist_ok=True)
        robot = with_tool(result.robot, tool.tcp2cam) if tool is not None else None
        paths = save_robot_calibration(folder, result, result.nominal, robot=robot, tool=tool)
        self._log.say(f"robot calibration saved to {paths[0]} and {paths[1]}")
        return paths
