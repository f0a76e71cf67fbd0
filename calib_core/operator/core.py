"""The operator core: the program's state and workflow without a window.

One object holds the cell (:class:`~calib_core.operator.cell.Cell`), the devices (the controller
link, from a :class:`~calib_core.operator.site.Site`) and the workflow (the target and its pairs
in the :class:`CalibrationSession`, the task location, options, corrections, moves and how they
ended). It declares typed psygnal events; the window, the command line, the recorder
(:mod:`calib_core.operator.recording_tap`) and the tests subscribe.

Threads: the link calls back on its reader thread. The core hands those calls to ``call_soon``
(default: run at once), so its state changes and its events happen on the owner's thread; the
window passes a function that queues them into the Qt event loop.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from psygnal import Signal

from calib_core.calibration.commands import SetTaskApproach
from calib_core.calibration.session import CalibrationError, CalibrationSession
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import OperatorError
from calib_core.link.driver import ControllerLink
from calib_core.calibration.verdict import ResultVerdict, judge
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.link.joint_history import ControllerClock, JointHistory
from calib_core.link.link_types import LinkState, MoveHandle, TimedSample
from calib_core.operator.cell import Cell
from calib_core.operator.cell_editor import CellEditor
from calib_core.operator.motion import Motion, MotionState, ended
from calib_core.operator.move_preview import MoveNeedsConfirmation, MovePreview, MoveRefused, joint_path, preview_move
from calib_core.robot.collision import CollisionWorld
from calib_core.operator.observations import HeldFrame, Observations
from calib_core.operator.session_files import SessionFiles
from calib_core.operator.site import Site
from calib_core.robot import solve_ik
from calib_core.scene import SceneItem
from calib_core.workcell import TaskLocation


class OperatorCore(SessionFiles):
    """Events (psygnal): ``joints_changed(q)`` (model joints, deg/mm), ``sample_received(sample, q)``
    (every joint sample, with its model joints), ``link_state(text)``, ``message(text)`` (for a
    status line), ``solved()``, ``task_changed(name)``, ``camera_model_changed()``,
    ``scene_changed()``, ``move_finished(what, error)`` (``error`` empty when the move arrived),
    ``frame_observed(frame)``, ``correction_stored(correction)``, ``event(kind, detail)``
    (operator actions worth recording), ``still_changed(held)`` (the frame held for picking, a
    :class:`~calib_core.operator.observations.HeldFrame`, or ``None`` when released),
    ``motion_changed(state)`` (a :class:`~calib_core.operator.motion.MotionState`),
    ``move_previewed(preview)`` (a :class:`~calib_core.operator.move_preview.MovePreview`, before
    every move, sent or not)."""

    joints_changed = Signal(object)
    sample_received = Signal(object, object)
    link_state = Signal(str)
    message = Signal(str)
    solved = Signal()
    task_changed = Signal(str)
    camera_model_changed = Signal()
    scene_changed = Signal()
    move_finished = Signal(str, str)
    frame_observed = Signal(object)
    correction_stored = Signal(object)
    event = Signal(str, object)
    still_changed = Signal(object)
    motion_changed = Signal(object)
    move_previewed = Signal(object)

    def __init__(self, cell: Cell, site: Site | None = None, *, call_soon: Callable[..., None] | None = None):
        self.cell = cell
        self.site = site
        self._call_soon = call_soon or (lambda fn, *args: fn(*args))
        self.session = CalibrationSession()
        self.joints_deg = cell.home_joints
        self.task: TaskLocation | None = next(iter(self.workcell.task_locations.values()), None)
        if self.task is not None and self.task.component:
            self.session.set_target(self.task.component)
        self.link: ControllerLink | None = None
        self.recorder = None
        self._tap = None
        self.replaying = False
        self.last_sample_s: float | None = None
        self.scene_extras: list[SceneItem] = []
        """Things put into the cell for a while (a calibration board), drawn in the CAD views."""
        self.revision = 0
        """Counts the changes of what a workspace holds (pairs, results, corrections, task locations, the
        target): the autosave writes only when it moved."""
        for signal in (self.session.pairs.changed, self.session.corrections.changed, self.session.undo.changed, self.session.changed, self.task_changed):
            signal.connect(self._count_change)
        self.current_pair: int | None = None
        """The pair being made: picked, not yet accepted (a click on the image moves its point)."""
        self.scene_version = 0
        """Counts the changes of what the CAD views show (components edited, a board put up)."""
        self.editor = CellEditor(self)
        """Edits of the cell (components, features, task locations), undoable, saved back to its file."""
        self.live = Observations(JointHistory(rule=self.workcell.safety.settle_rule, joint_names=self.robot.joint_names))
        """The live frames and the link's joint history."""
        self.observations = self.live
        self.controller_clock = ControllerClock()
        """Stamps each joint sample with its controller time on the host clock (not its arrival)."""
        """What picks are stamped by: the live one, or a recording's while it is replayed."""
        self.motion = MotionState()
        self._pending_move: tuple[str, MoveHandle] | None = None
        self._collision_world = None  # built on the first move preview, again when the cell changes
        self._collision_version = -1
        self.session.judge = self._judge
        self.session.pairs.changed.connect(self._release_unused_still)

    def _count_change(self, *_) -> None:
        self.revision += 1

    # --- the cell -------------------------------------------------------------------------------
    @property
    def workcell(self):
        return self.cell.workcell

    @property
    def robot(self):
        return self.cell.robot

    @property
    def intrinsics(self) -> Intrinsics:
        return self.cell.intrinsics

    # --- robot and link -----------------------------------------------------------------------
    def start_controller(self) -> str:
        """Ask the site for its controller and connect to it; returns the link URL."""
        if self.site is None:
            raise CalibrationError("no site: give a controller (--port) or use the simulated cell")
        url = self.site.start_controller()
        self.connect_link(url)
        return url

    def connect_link(self, url: str, rate_hz: float = 50.0) -> None:
        if self.link is not None:
            self.link.close()
        self.link = ControllerLink(url, mode="stream", rate_hz=rate_hz, n_joints=self.robot.n_joints)
        self.link.on_sample(lambda sample: self._call_soon(self.observe_sample, sample))
        self.link.on_state(lambda state, why: self._call_soon(self._on_link_state, state.value, why))
        if self.site is not None:
            self.site.attach(self.link)
        self.link.start()
        self.message.emit(f"controller link: {url}")

    def _on_link_state(self, state: str, why: str) -> None:
        self.record_event("link_state", state=state, why=why)
        if state in ("down", "closed"):
            # The device is gone: the robot may move unseen, no earlier sample vouches for a later frame.
            # (A stale link, open but late, leaves a gap in the samples: the settle rule sees it.)
            self.live.history.forget(time.monotonic())
            if self.motion.motion is Motion.MOVING:
                self._set_motion(MotionState(Motion.UNKNOWN, self.motion.what, f"the link went {state} during the move to {self.motion.what}; waiting for a fresh joint sample"))
        self.link_state.emit(f"{state}: {why}")

    def _set_motion(self, state: MotionState) -> None:
        self.motion = state
        self.motion_changed.emit(state)

    def record_event(self, kind: str, **detail) -> None:
        """An operator action or a link change worth keeping in a recording."""
        self.event.emit(kind, detail)

    def observe_sample(self, sample: TimedSample) -> None:
        """A joint sample from the link (its reader thread hands it here through ``call_soon``)."""
        self.last_sample_s = time.monotonic()
        q = self.cell.joint_map.to_model(sample.joints_deg)
        restarts = self.controller_clock.restarts
        t_sent = self.controller_clock.stamp(sample.t_host_s, sample.sample.t_ms / 1000.0)
        if self.controller_clock.restarts != restarts:
            self.live.history.forget(sample.t_host_s)  # a restarted controller: nothing before vouches for now
        self.live.history.add(t_sent, q)
        if self.motion.motion is Motion.UNKNOWN:
            pending = self._pending_move
            if pending is not None and not pending[1].finished:
                self._set_motion(MotionState(Motion.MOVING, pending[0], "the link is back"))
            else:
                self._set_motion(MotionState(Motion.IDLE, self.motion.what, "the link is back: the robot stands where its joints say"))
        self.sample_received.emit(sample, q)
        if self.replaying:
            return  # the recorded joints drive the views while a recording is replayed
        self.joints_deg = q
        self.joints_changed.emit(self.joints_deg)

    def show_replayed_joints(self, joints_deg) -> None:
        """Joints from a recording being replayed: the CAD views follow them, the robot does not move."""
        self.joints_deg = np.array(joints_deg, dtype=float)
        self.joints_changed.emit(self.joints_deg)

    @property
    def link_up(self) -> bool:
        return self.link is not None and self.link.state is LinkState.UP

    def move_to(self, target2base: np.ndarray, what: str, *, wait: bool = False, timeout_s: float = 30.0, confirmed: bool = False, allowed_contacts: frozenset[str] = frozenset()) -> MoveHandle:
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

    def move_joints(self, q, what: str, *, wait: bool = False, timeout_s: float = 30.0, confirmed: bool = False, allowed_contacts: frozenset[str] = frozenset()) -> MoveHandle:
        """Move to model joints ``q`` (deg/mm) over the link; ``move_finished`` tells how it ended.
        The move is previewed first: refused (:class:`MoveRefused`) outside the limits or into a
        collision, and sent only with ``confirmed`` when it turns a joint further than the cell's
        ``confirm_joint_change_deg`` (:class:`MoveNeedsConfirmation`)."""
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
                raise MoveNeedsConfirmation(preview)
            self.record_event("move_confirmed", what=what, reasons=list(preview.confirm_reasons))
        handle = self.link.move_joints(self.cell.joint_map.to_controller(q), timeout_s=timeout_s)
        if not handle.sent:
            handle.wait(0)  # raises the link's reason
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

    def go_to_task(self, *, approach: bool = True, corrected: bool = False, wait: bool = False, confirmed: bool = False) -> MoveHandle:
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

    def set_task_approach(self, name: str, approach_mm: float) -> None:
        """Edit a task location's approach distance (mm): an undoable edit."""
        if abs(self.workcell.task(name).approach_mm - approach_mm) < 1e-9:
            return
        self.session.undo.push(SetTaskApproach(self.workcell.task_locations, name, approach_mm, self._task_edited))

    def _task_edited(self, name: str) -> None:
        if self.task is not None and self.task.name == name:
            self.task = self.workcell.task(name)
        self.task_changed.emit(name)

    def set_task(self, name: str) -> None:
        self.task = self.workcell.task(name)
        if self.task.component:
            self.session.set_target(self.task.component)
        self.session.rejudge()  # the task's tolerance is part of the verdict
        self.task_changed.emit(name)

    # --- the pair being made (the paper's Point and Accept) -------------------------------------------
    def pick_model_point(self, component: str, feature: str | None, point_world_mm) -> int:
        """*Point*, first half: a point on the target's model (3,) mm in base. A new model pick
        replaces a pair still waiting for its image point. Returns the pair's number."""
        pending = self.session.pairs.pending()
        if pending is not None:
            self.session.delete(pending.number)
        self.current_pair = self.session.pick_3d(component, feature, point_world_mm)
        return self.current_pair

    def pick_image_point(self, pixel) -> int:
        """*Point*, second half: the same point on the camera image (u, v) px. Until *Accept*, a
        second click moves it. The pick is made on the held frame; the first pick of a set holds
        the newest one, and only when the robot had settled before it (else
        :class:`~calib_core.operator.observations.NotSettledError`, nothing picked)."""
        session = self.session
        pending = session.pairs.pending()
        moving = pending is None and self.current_pair is not None and self.current_pair in [p.number for p in session.pairs]
        if pending is None and not moving:
            session.pick_2d(pixel)  # raises with what to do instead
        view = self._view_for_pick(self.current_pair if moving else pending.number)
        if moving:
            session.move_2d(self.current_pair, pixel, view)
        else:
            self.current_pair = session.pick_2d(pixel, view)
        return self.current_pair

    def _view_for_pick(self, number: int) -> ViewStamp:
        held = self.observations.still
        if held is None:
            held = self.hold_frame()
        others = [p for p in self.session.pairs if p.complete and p.number != number]
        self.check_same_state(others, held.stamp)
        return held.stamp

    def check_same_state(self, pairs, view: ViewStamp | None = None) -> None:
        """Refuse pairs from different robot states: each with ``view`` (or with the first)."""
        stamped = [p for p in pairs if p.view is not None]
        reference = view or (stamped[0].view if stamped else None)
        if reference is None:
            return
        other = [p for p in stamped if not p.view.same_state(reference)]
        if other:
            worst = max(other, key=lambda p: p.view.joint_difference(reference))
            names = ", ".join(str(p.number) for p in other)
            raise CalibrationError(
                f"pair{'s' if len(other) > 1 else ''} {names} {'were' if len(other) > 1 else 'was'} picked with the robot at another pose "
                f"(a joint differs by {worst.view.joint_difference(reference):.2f} deg from {reference.label}): "
                "one set of pairs must come from one robot pose. Delete them (or Clear), or go back to that pose"
            )

    # --- frames ---------------------------------------------------------------------------------
    def hold_frame(self) -> HeldFrame:
        """Hold the newest frame for picking (refused while the robot moves); ``still_changed``."""
        held = self.observations.hold()
        self.record_event("frame_held", frame_index=held.stamp.frame_index, t_capture_s=held.stamp.t_capture_s, joints_deg=list(held.stamp.joints_deg))
        self.still_changed.emit(held)
        return held

    def stamp_frame(self, frame) -> ViewStamp:
        """``frame``'s stamp (its joints at capture), refused while the robot was not settled."""
        return self.observations.stamp(frame)

    def release_frame(self) -> None:
        """Back to the live image for picking (the pairs keep their stamps)."""
        if self.observations.still is not None:
            self.observations.release()
            self.still_changed.emit(None)

    def _release_unused_still(self, *_) -> None:
        if self.observations.still is not None and not any(p.complete for p in self.session.pairs):
            self.release_frame()

    def robot_settled(self):
        """Whether the robot is still now (a :class:`~calib_core.link.joint_history.Stillness`), from
        the newest frame's time (or the newest sample's)."""
        obs = self.observations
        t = obs.latest.t_host_s if obs.latest is not None else obs.history.latest_s
        if t is None:
            return obs.history.stillness(time.monotonic())
        return obs.history.stillness(t)

    def _judge(self, estimate) -> ResultVerdict:
        tolerance = self.task.tolerance_mm if self.task is not None else None
        return judge(estimate, self.workcell.safety, tolerance) if tolerance is not None else judge(estimate, self.workcell.safety)

    def accept_pair(self) -> int:
        """*Accept*: the pair being made is done. Returns its number."""
        pending = self.session.pairs.pending()
        if pending is not None:
            raise OperatorError(f"pair {pending.number} ({pending.feature or 'surface point'}) has no point on the camera image yet: click it there, then Accept")
        if self.current_pair is None:
            raise OperatorError("nothing to accept: pick a point on the model (virtual camera), then the same point on the camera image")
        number, self.current_pair = self.current_pair, None
        self.record_event("pair_accepted", number=number)
        return number

    def delete_pair(self, number: int | None = None) -> int:
        """Delete pair ``number`` (default: the pair being made). Undoable."""
        number = number if number is not None else self.current_pair
        if number is None:
            raise OperatorError("select a pair in the table to delete it")
        self.session.delete(number)
        if number == self.current_pair:
            self.current_pair = None
        return number

    def undo(self) -> str | None:
        """Undo the last edit (its label, None if there was none); the pair being made is let go."""
        self.current_pair = None
        return self.session.undo.undo()

    def redo(self) -> str | None:
        return self.session.undo.redo()

    def choose_candidate(self, index: int) -> None:
        """Take solution ``index`` of an ambiguous solve (undoable)."""
        self.session.choose_candidate(index)
        self.record_event("candidate_chosen", index=index, solution=index + 1)

    # --- frames of reference -------------------------------------------------------------------
    def model_cam2world(self) -> np.ndarray:
        return self.robot.fk(self.joints_deg, "camera")

    def model_tcp2base(self) -> np.ndarray:
        return self.robot.fk(self.joints_deg, "tcp")

    def observe_frame(self, frame, *, replayed: bool = False) -> None:
        """A camera frame arrived: from the camera (the window's worker, a command-line loop) or,
        with ``replayed``, from the recording being replayed. Live frames are ignored during a replay."""
        if self.replaying != replayed:
            return
        self.observations.observe(frame)
        self.frame_observed.emit(frame)

    def begin_replay(self, history: JointHistory, name: str) -> None:
        """A recording is being replayed: its frames and joints stand in for the live ones."""
        self.release_frame()
        self.replaying = True
        self.observations = Observations(history, source=name)

    def end_replay(self) -> None:
        self.release_frame()
        self.replaying = False
        self.observations = self.live

    # --- calibration -------------------------------------------------------------------------
    def calibrate(self):
        target = self.session.target
        if target is None:
            raise CalibrationError("choose the target object first")
        obj2world = self.workcell.component(target).item2world
        use = self.session.pairs.usable()
        unbound = [p.number for p in use if p.view is None]
        if unbound:
            raise CalibrationError(
                f"pair{'s' if len(unbound) > 1 else ''} {', '.join(map(str, unbound))} {'carry' if len(unbound) > 1 else 'carries'} no robot pose "
                "(picked outside the program's frames, or saved by an older videocal): pick the image point again, on a frame of this pose"
            )
        self.check_same_state(use)
        joints = np.array(use[0].view.joints_deg) if use else self.joints_deg
        self.current_pair = None
        result = self.session.calibrate(self.intrinsics, obj2world, self.robot.fk(joints, "camera"), self.robot.fk(joints, "tcp"), joints)
        self.solved.emit()
        return result

    def store_correction(self, *, confirmation: str = ""):
        """Store the last result for the task location. One that is not ``ok`` needs ``confirmation``
        (who accepted it and why: kept with the correction and recorded)."""
        if self.task is None:
            raise CalibrationError("choose the task location the correction is for")
        c = self.session.store_correction(self.task.name, confirmation=confirmation)
        if c.confirmation:
            self.record_event("correction_confirmed", task=c.task, verdict=c.verdict, confirmation=c.confirmation)
        self.correction_stored.emit(c)
        self.message.emit(f"correction stored for {self.task.name}: {np.linalg.norm(c.displacement_mm):.2f} mm, {np.linalg.norm(c.rotation_deg):.3f} deg")
        return c

    def apply_hand_eye_file(self, path) -> None:
        """Use a measured camera mounting (``videocal calibrate-hand-eye`` output) in place of the model's."""
        from calib_core.vision.hand_eye_io import load_cam2flange

        self.apply_cam2flange(load_cam2flange(path), f"camera mounting from {path}")

    def apply_cam2flange(self, cam2flange: np.ndarray, why: str = "camera mounting replaced") -> None:
        """Use a measured camera mounting (4, 4) mm on the flange in place of the modelled one."""
        flange = self.robot.frame_placement("flange")
        self.robot.set_frame_placement("camera", flange @ np.asarray(cam2flange, dtype=float))
        self.camera_model_changed.emit()
        self.message.emit(why)

    def apply_intrinsics(self, intrinsics: Intrinsics, why: str = "camera intrinsics replaced") -> None:
        """Use calibrated intrinsics for picking, solving and the virtual camera (the size must match)."""
        if (intrinsics.width, intrinsics.height) != (self.intrinsics.width, self.intrinsics.height):
            raise CalibrationError(f"the calibration is for {intrinsics.width} x {intrinsics.height} px images, the camera gives {self.intrinsics.width} x {self.intrinsics.height} px")
        self.use_intrinsics(intrinsics)
        self.message.emit(why)

    def use_intrinsics(self, intrinsics: Intrinsics) -> None:
        """Picks, solves and the virtual camera use ``intrinsics`` from now on (a replay uses the
        recording's camera while it plays, whatever its size)."""
        if intrinsics != self.cell.intrinsics:
            self.cell.intrinsics = intrinsics
            self.camera_model_changed.emit()

    # --- the calibration board --------------------------------------------------------------------
    def board_placement(self, spec) -> np.ndarray:
        """Where the hand-eye board stands: the workcell's ``hand_eye_board`` placement, or upright
        in front of the robot within its reach. ``board2base`` (4, 4) mm."""
        from calib_core.vision.board_placement import board_in_cell

        return board_in_cell(spec, self.workcell, self.robot)

    def show_calibration_board(self, spec, on: bool = True) -> np.ndarray:
        """Put a ChArUco board up in the cell (or take it down). Returns its ``board2base`` (4, 4) mm."""
        from calib_core.vision.board import board_item

        board2base = self.board_placement(spec)
        self.scene_extras = [board_item(spec, board2base)] if on else []
        if self.site is not None:
            self.site.put_up(list(self.scene_extras))
        self.scene_version += 1
        self.scene_changed.emit()
        return board2base

    def board_view_plan(self, spec, n: int = 12) -> list[np.ndarray]:
        """Joint vectors (deg/mm) from which the modelled camera sees the board from different
        directions, in an order whose every move (from the current joints on) is free of collisions
        with the robot itself and the cell (the board among it); a pose without such a path is left out."""
        from calib_core.vision.board_placement import board_view_joints

        world = self.collision_world()
        plan, q = [], np.asarray(self.joints_deg, dtype=float)
        for goal in board_view_joints(self.robot, self.cell.home_joints, spec, self.board_placement(spec), n):
            if not any(world.check(p) for p in joint_path(q, goal)):
                plan.append(goal)
                q = goal
        return plan

    def close(self) -> None:
        self.stop_recording()
        if self.link is not None:
            self.link.close()
        if self.site is not None:
            self.site.close()
