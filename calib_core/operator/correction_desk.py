"""The operator core's correction desk: where a look counts (:mod:`~calib_core.calibration.look_place`), storing it
as the task location's correction (or keeping it as a measurement), the conversion a look from elsewhere needs, and
*Verify* after the corrected task was executed. Every stored correction is announced by ``correction_stored``.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.desk``), given the cell, the session, the task
choice, the arm (how the last move ended), the picking (the solve Verify makes), the robot calibration (the
model a look is fused with, the measured tool) and the log.
"""

from __future__ import annotations

import numpy as np
from psygnal import Signal

from calib_core.calibration.correction_from_look import StoreLook
from calib_core.calibration.look_place import LookNotAtTask, LookPlace, place_of_look
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.calibration.verification import Verification, verify
from calib_core.calibration.view_stamp import SAME_STATE_DEG
from calib_core.frames import concat, invert, pose_difference
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.motion import Motion
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.picking import Picking
from calib_core.operator.robot_calibrating import RobotCalibrating
from calib_core.operator.task_choice import TaskChoice


class CorrectionDesk:
    """Event: ``correction_stored(correction)`` after a correction or a measurement is stored."""

    correction_stored = Signal(object)

    def __init__(
        self,
        cell: Cell,
        session: CalibrationSession,
        tasks: TaskChoice,
        arm: Arm,
        picking: Picking,
        robot_calibration: RobotCalibrating,
        log: OperatorLog,
    ):
        self._cell, self._session, self._tasks, self._arm, self._picking, self._robot_calibration, self._log = (
            cell,
            session,
            tasks,
            arm,
            picking,
            robot_calibration,
            log,
        )

    @property
    def task(self):
        return self._tasks.task

    def look_place(self) -> LookPlace | None:
        """Where the last result's look was made against the chosen task location (``None`` before a
        solve, without a task location or for a look that carries no robot pose)."""
        context = self._session.result.context
        if self.task is None or context is None or context.joints_deg is None:
            return None
        corrected = None
        if self._session.corrections.latest(self.task.name) is not None:
            corrected = self._session.corrections.corrected_target(self.task.name, self.task.tcp2base)
        return place_of_look(self.task, self._cell.robot.fk(context.joints_deg, "tcp"), corrected, context.view_sources)

    def store_correction(self, *, confirmation: str = "", convert: str = ""):
        """Store the last result as the task location's correction. Only a look made live at the task's
        pose (or its corrected pose) counts (:mod:`~calib_core.calibration.look_place`); any other raises
        :class:`LookNotAtTask` unless ``convert`` says who converted it and why (kept with the correction
        and recorded). One that is not ``ok`` needs ``confirmation`` likewise. With a robot calibration
        applied, the look is stored fused with the calibrated model
        (:meth:`~calib_core.operator.robot_calibrating.RobotCalibrating.look_fused_with_robot`); with a
        measured tool (:meth:`~calib_core.operator.tool_measuring.ToolMeasuring.measure_tool`) its covariance is in the
        stored 1-sigma either way."""
        if self.task is None:
            raise CalibrationError("choose the task location the correction is for")
        # said first: a look that changed since is no look at all
        self._session.result.storable_estimate(self._session.pairs.usable())
        place = self.look_place()
        if place is None:
            raise CalibrationError(
                "the look carries no robot pose: pick the image points again on a frame of this pose, then Calibrate"
            )
        if not place.counts and not convert.strip():
            raise LookNotAtTask(place, *self._conversion_change())
        tool, context = self._robot_calibration.measured_tool, self._session.result.context
        tool_covariance = None
        if tool is not None and context.joints_deg is not None:
            tool_covariance = tool.covariance_in_base(self._cell.robot.fk(context.joints_deg, "camera"))
        source = "" if place.counts else f"converted: {place.text}; {convert.strip()}"
        if source:
            source = (f"pairs {', '.join(map(str, context.numbers))}; " if context.numbers else "edges; ") + source
        store = StoreLook(
            self._session,
            self.task.name,
            source,
            confirmation=confirmation,
            fused=self._robot_calibration.look_fused_with_robot(self._session.result.estimate),
            tool_covariance=tool_covariance,
        )
        c = self._session.undo.push(store).correction
        if not place.counts:
            self._log.record(
                "look_converted",
                task=c.task,
                at=place.at,
                offset_mm=place.offset_mm,
                offset_deg=place.offset_deg,
                source=place.source,
                conversion=convert.strip(),
            )
        if c.confirmation:
            self._log.record("correction_confirmed", task=c.task, verdict=c.verdict, confirmation=c.confirmation)
        self.correction_stored.emit(c)
        self._log.say(
            f"correction stored for {self.task.name}: {np.linalg.norm(c.displacement_mm):.2f} mm, "
            f"{np.linalg.norm(c.rotation_deg):.3f} deg"
        )
        return c

    def store_measurement(self):
        """Keep the last result as what it is: a measurement at its own pose, in the task location's
        history, never commanded."""
        if self.task is None:
            raise CalibrationError("choose the task location the measurement belongs with")
        place = self.look_place()
        where = place.text if place is not None else "a look without a robot pose"
        store = StoreLook(self._session, self.task.name, f"measurement: {where}", kind="measurement")
        c = self._session.undo.push(store).correction
        self.correction_stored.emit(c)
        self._log.say(f"measurement kept with {self.task.name} ({where}); the task's correction is unchanged")
        return c

    def _conversion_change(self) -> tuple[float, float]:
        """How far the target commanded for the task would move (mm, deg) if the last result became its correction."""
        r, task = self._session.result.estimate, self.task
        now = self._session.corrections.corrected_target(task.name, task.tcp2base)
        delta = concat(
            invert(r.tcp2base_model), r.tcp2base_measured
        )  # tcp_real = delta @ tcp_model, as a stored correction's
        converted = concat(task.tcp2base, invert(delta))
        d, rot = pose_difference(converted, now)
        return float(np.linalg.norm(d)), float(np.linalg.norm(rot))

    def verify(self) -> Verification:
        """*Verify*: after executing the task with its correction, solve the pairs picked from there and
        report the tool's remaining error against the task location with its 1-sigma, and whether this look
        agrees with the one the correction came from. Kept in the correction table's history."""
        task = self.task
        if task is None:
            raise CalibrationError("choose the task location to verify")
        correction = self._session.corrections.latest(task.name)
        if correction is None:
            raise CalibrationError(f"no stored correction for {task.name}: calibrate, store and execute one first")
        executed = f"{task.name} (task, corrected)"
        motion = self._arm.state
        if motion.motion is not Motion.ARRIVED or motion.what != executed:
            raise CalibrationError(
                "execute the task with its correction first (Go to task, corrected), then pick the pairs from there "
                f"and Verify ({motion.text})"
            )
        use = self._session.pairs.usable()
        here = [
            p
            for p in use
            if p.view is not None
            and np.max(np.abs(np.array(p.view.joints_deg) - self._arm.joints_deg)) <= SAME_STATE_DEG
        ]
        if len(here) != len(use) or not use:
            raise CalibrationError(
                "the pairs were not picked from where the robot stands now: Clear, pick them again here, then Verify"
            )
        look = self._picking.calibrate()
        v = verify(task.name, task.tcp2base, correction, look, task.tolerance_mm)
        self._session.corrections.add_verification(v)
        self._log.record(
            "verified",
            task=task.name,
            remaining_mm=v.remaining_mm.tolist(),
            std_remaining_mm=v.std_remaining_mm.tolist(),
            disagreement_mm=v.disagreement_mm,
            agree=v.agree,
            within_tolerance=v.within_tolerance,
            tolerance_mm=v.tolerance_mm,
        )
        self._log.say(v.text)
        return v
