"""Moving the robot from the operator core: every move previewed (limits, singularities,
collisions, joint change: :mod:`calib_core.operator.move_preview`), refused or held for a
confirmation when it must be, sent over the link, and followed to the controller's answer.

A mixin of :class:`~calib_core.operator.core.OperatorCore`: it uses the core's robot, cell, link,
joints and events.
"""

from __future__ import annotations

import time

import numpy as np

from calib_core.calibration.session import CalibrationError
from calib_core.link.link_types import MoveHandle
from calib_core.operator.motion import Motion, MotionState, ended
from calib_core.operator.move_preview import Confirmation, MoveNeedsConfirmation, MovePreview, MoveRefused, preview_move
from calib_core.robot import solve_ik
from calib_core.robot.collision import CollisionWorld


class Moves:
    """Moves of the core's robot (``motion`` says how the last one stands)."""

    def _set_motion(self, state: MotionState) -> None:
        self.motion = state
        self.motion_changed.emit(state)

    def move_to(self, target2base: np.ndarray, what: str, *, wait: bool = False, timeout_s: float = 30.0, confirmed: bool | Confirmation = False, allowed_contacts: frozenset[str] = frozenset()) -> MoveHandle:
        """IK for the TCP target (4, 4) mm in base from the current joints, then a joint move."""
        q = solve_ik(self.robot, target2base, self.joints_deg).q_deg
        return self.move_joints(q, what, wait=wait, timeout_s=timeout_s, confirmed=confirmed, allowed_contacts=allowed_contacts)

    def collision_world(self) -> CollisionWorld:
        """The robot's collision bodies and the cell's components (and what is put up in it, a board)."""
        if self._collision_world is None or self._collision_version != self.scene_version:
            self._collision_world = CollisionWorld(self.robot, list(self.workcell.components) + list(self.scene_extras), self.cell.home_joints)
            self._collision_version = self.scene_version
        return self._collision_world

    def preview_move(self, q, what: str, allowed_contacts: frozenset[str] = frozenset()) -> MovePreview:
        """The move from the current joints to ``q`` (deg/mm), checked; ``move_previewed`` shows it."""
        preview = preview_move(self.robot, self.collision_world(), self.joints_deg, q, what, self.workcell.safety, allowed_contacts)
        self.move_previewed.emit(preview)
        return preview

    def move_joints(self, q, what: str, *, wait: bool = False, timeout_s: float = 30.0, confirmed: bool | Confirmation = False, allowed_contacts: frozenset[str] = frozenset()) -> MoveHandle:
        """Move to model joints ``q`` (deg/mm) over the link; ``move_finished`` tells how it ended.
        The move is previewed first: refused (:class:`MoveRefused`) outside the limits or into a
        collision, and sent only with ``confirmed`` when it turns a joint further than the cell's
        ``confirm_joint_change_deg`` (:class:`MoveNeedsConfirmation`). ``confirmed``: ``True`` (a
        script's), or the prompt's :class:`Confirmation`, void once a Stop was sent after it."""
        if self.replaying:
            raise CalibrationError("a recording is being replayed: the views show it, not the robot; close the replay before moving the robot")
        if self.link is None:
            raise CalibrationError("no controller link: connect one first")
        q = self.robot.check_joints(q)
        outside = np.flatnonzero(~self.robot.within_limits(q))
        if len(outside):
            j = int(outside[0])
            raise CalibrationError(
                f"not moving to {what}: joint {self.robot.joint_names[j]} target {q[j]:.2f} {self.robot.joint_units[j]} is outside its limits "
                f"[{self.robot.lower_limits_deg[j]:g}, {self.robot.upper_limits_deg[j]:g}]"
            )
        if self.motion.motion is Motion.UNKNOWN:
            raise CalibrationError(f"not moving to {what}: the robot's pose is unknown (the link dropped); wait for a fresh joint sample")
        preview = self.preview_move(q, what, allowed_contacts)
        if preview.blocked:
            raise MoveRefused(preview)
        if preview.needs_confirmation:
            if not confirmed:
                raise MoveNeedsConfirmation(preview, Confirmation(what, self.stops_sent))
            if isinstance(confirmed, Confirmation) and (confirmed.stops_seen != self.stops_sent or confirmed.what != what):
                raise CalibrationError(f"not moving to {what}: the robot was stopped after this move was asked for; ask for it again")
            self.record_event("move_confirmed", what=what, reasons=list(preview.confirm_reasons))
        handle = self.link.move_joints(self.link.joint_map.to_controller(q), timeout_s=timeout_s)
        if not handle.sent:
            handle.wait(0)  # raises the link's reason
        self.last_move_sent_s = time.monotonic()  # frames from before it show the old pose (board captures)
        self.message.emit(f"moving to {what}: joints {', '.join(f'{v:.1f}' for v in q)}")
        self._set_motion(MotionState(Motion.MOVING, what))
        self._pending_move = (what, handle)
        handle.on_finished(lambda h: self._call_soon(self._move_ended, what, h))
        if wait:
            handle.wait(timeout_s)
        return handle

    def _move_ended(self, what: str, handle: MoveHandle) -> None:
        error = handle.error
        if self.motion.motion is Motion.MOVING and self.motion.what == what:
            self._set_motion(ended(what, error))
        self.record_event("move_finished", what=what, error=str(error) if error else "")
        self.move_finished.emit(what, str(error) if error else "")
        self.message.emit(f"move to {what} failed: {error}" if error else f"arrived at {what}")

    def go_to_task(self, *, approach: bool = True, corrected: bool = False, wait: bool = False, confirmed: bool | Confirmation = False) -> MoveHandle:
        if self.task is None:
            raise CalibrationError("choose a task location first")
        target = self.task.approach2base if approach else self.task.tcp2base
        if corrected:
            if self.session.corrections.latest(self.task.name) is None:
                raise CalibrationError(f"no stored correction for {self.task.name}: calibrate and store one first")
            target = self.session.corrections.corrected_target(self.task.name, target)
        what = f"{self.task.name} ({'approach' if approach else 'task'}{', corrected' if corrected else ''})"
        # at the task pose itself the tool works on the task's object: touching it is the task
        allowed = frozenset({self.task.component}) if (not approach and self.task.component) else frozenset()
        return self.move_to(target, what, wait=wait, confirmed=confirmed, allowed_contacts=allowed)

    def stop_robot(self) -> bool:
        """Stop now (``$STP``): the controller halts the robot where it is; the running move ends with
        its ``STOPPED`` reason. True if the stop went out."""
        # Every prompt still waiting is void, link or not: a Move pressed after Stop must not move the robot.
        self.stops_sent += 1
        self.prompts_withdrawn.emit()
        if self.link is None:
            raise CalibrationError("no controller link: nothing to stop")
        sent = self.link.stop()
        self.record_event("stop", sent=sent, during=self.motion.what if self.motion.motion is Motion.MOVING else "")
        self.message.emit("stop sent to the controller" if sent else f"stop NOT sent: the link is {self.link.state.value}")
        return sent
