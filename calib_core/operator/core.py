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
from calib_core.frames import concat, invert
from calib_core.connectors.controller import ControllerConnector, ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.calibration.verdict import ResultVerdict, judge
from calib_core.link.joint_history import ControllerClock, JointHistory
from calib_core.link.link_types import LinkState, MoveHandle, TimedSample
from calib_core.operator.cell import Cell
from calib_core.operator.cell_editor import CellEditor
from calib_core.operator.correction_desk import CorrectionDesk
from calib_core.operator.motion import Motion, MotionState
from calib_core.operator.move_preview import joint_path
from calib_core.operator.observations import Observations
from calib_core.operator.moves import Moves
from calib_core.operator.picking import Picking
from calib_core.operator.point_finding import PointFinding
from calib_core.operator.robot_calibrating import RobotCalibrating
from calib_core.operator.session_files import SessionFiles
from calib_core.operator.site import Site
from calib_core.operator.tool_measuring import ToolMeasuring
from calib_core.scene import SceneItem
from calib_core.workcell import TaskLocation


class OperatorCore(SessionFiles, Picking, Moves, PointFinding, RobotCalibrating, ToolMeasuring, CorrectionDesk):
    """Events (psygnal): ``joints_changed(q)`` (model joints, deg/mm), ``sample_received(sample, q)``
    (every joint sample, with its model joints), ``link_state(text)``, ``message(text)`` (for a
    status line), ``solved()``, ``task_changed(name)``, ``camera_model_changed()``,
    ``scene_changed()``, ``move_finished(what, error)`` (``error`` empty when the move arrived),
    ``correction_stored(correction)``, ``event(kind, detail)``
    (operator actions worth recording), ``motion_changed(state)`` (a :class:`~calib_core.operator.motion.MotionState`),
    ``move_previewed(preview)`` (a :class:`~calib_core.operator.move_preview.MovePreview`, before
    every move, sent or not), ``prompts_withdrawn()`` (a Stop voided every move prompt still waiting).
    Frames and the held one are :attr:`observations`' events (``frame_observed``, ``still_changed``)."""

    joints_changed = Signal(object)
    sample_received = Signal(object, object)
    link_state = Signal(str)
    message = Signal(str)
    solved = Signal()
    task_changed = Signal(str)
    camera_model_changed = Signal()
    scene_changed = Signal()
    move_finished = Signal(str, str)
    correction_stored = Signal(object)
    event = Signal(str, object)
    motion_changed = Signal(object)
    move_previewed = Signal(object)
    points_found = Signal(object)
    prompts_withdrawn = Signal()

    def __init__(self, cell: Cell, site: Site | None = None, *, call_soon: Callable[..., None] | None = None):
        self.cell = cell
        self.site = site
        self._call_soon = call_soon or (lambda fn, *args: fn(*args))
        self.session = CalibrationSession()
        self.joints_deg = cell.home_joints
        self.task: TaskLocation | None = next(iter(self.workcell.task_locations.values()), None)
        if self.task is not None and self.task.component:
            self.session.set_target(self.task.component)
        self.link: ControllerConnector | None = None
        self.recorder = None
        self._tap = None
        self.last_sample_s: float | None = None
        self.scene_extras: list[SceneItem] = []
        self.stops_sent = 0  # a prompt's confirmation carries the count it saw: a later Stop voids it
        self.last_move_sent_s: float | None = None  # host monotonic s
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
        self.observations = Observations(JointHistory(rule=self.workcell.safety.settle_rule, joint_names=self.robot.joint_names), margin_s=lambda: self.controller_clock.spread_s)
        """The frames (live, or a recording's while it is replayed), the held one, and the joint history
        that stamps them."""
        self.controller_clock = ControllerClock()
        """Stamps each joint sample with its controller time on the host clock (not its arrival)."""
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
    def start_controller(self) -> str | None:
        """Ask the site for its controller and connect to it; returns the controller URL (``None``: the
        site has no controller, a camera alone)."""
        if self.site is None:
            raise CalibrationError("no site: give a controller (--port) or use the simulated cell")
        url = self.site.start_controller()
        if url is not None:
            self.connect_link(url, options=getattr(self.site, "controller_options", None))
        return url

    def connect_link(self, url: str, rate_hz: float = 50.0, options: dict | None = None) -> None:
        """Open the controller connector registered for ``url``'s scheme and start it."""
        if self.link is not None:
            self.link.close()
            self.link = None
        context = ControllerContext.of(self.robot, self.cell.joint_map, rate_hz, options)
        self.link = open_controller(url, context)
        self.link.sample_received.connect(lambda sample: self._call_soon(self.observe_sample, sample))
        self.link.state_changed.connect(lambda state, why: self._call_soon(self._on_link_state, state.value, why))
        self.link.auth_changed.connect(lambda state, failure: self._call_soon(self._on_link_auth, state.value, failure))
        status = getattr(self.link, "status_changed", None)  # a controller's own state (a UR's protective stop, speed slider)
        if status is not None:
            status.connect(lambda text: self._call_soon(self._on_link_status, text))
        if self.site is not None:
            self.site.attach(self.link)
        self.link.start()
        self.message.emit(f"controller link: {url}")
        if hasattr(self.link, "publish_static_transforms"):  # a ROS 2 cell: the results on /tf_static too
            for signal in (self.camera_model_changed, self.correction_stored):
                signal.connect(self._publish_static_transforms, unique=True)
            self._publish_static_transforms()

    def static_transforms(self) -> list[tuple[str, str, np.ndarray]]:
        """What the cell's ROS side is told: ``(parent, child, child2parent_mm)`` for the camera mounting in use
        (``videocal_camera`` on the flange; z along the optical axis, x right, y down: ROS's optical frame) and
        each task's corrected target (``videocal/<task>`` in the base frame; the correction, or the plan if none)."""
        frames = self.workcell.robot_spec.frames
        flange, base = str(frames.get("flange") or "flange"), str(frames.get("base") or "base_link")
        q = self.joints_deg
        out = [(flange, "videocal_camera", concat(self.robot.fk(q, "camera"), invert(self.robot.fk(q, "flange"))))]
        for name, task in self.workcell.task_locations.items():
            out.append((base, f"videocal/{name}", self.session.corrections.corrected_target(name, task.tcp2base)))
        return out

    def _publish_static_transforms(self, *_) -> None:
        link = self.link
        if link is None or not hasattr(link, "publish_static_transforms"):
            return
        try:
            link.publish_static_transforms(self.static_transforms())
        except Exception as exc:  # the ROS side is an output: its failure must not stop the calibration
            self.message.emit(f"could not publish /tf_static: {exc}")

    def _on_link_state(self, state: str, why: str) -> None:
        self.record_event("link_state", state=state, why=why)
        if state in ("down", "closed"):
            # The device is gone: the robot may move unseen, no earlier sample vouches for a later frame.
            # (A stale link, open but late, leaves a gap in the samples: the settle rule sees it.)
            self.observations.live_history.forget(time.monotonic())
            if self.motion.motion is Motion.MOVING:
                self._set_motion(MotionState(Motion.UNKNOWN, self.motion.what, f"the link went {state} during the move to {self.motion.what}; waiting for a fresh joint sample"))
        self.link_state.emit(f"{state}: {why}")

    def _on_link_status(self, text: str) -> None:
        self.record_event("controller_status", text=text)
        self.message.emit(f"controller: {text}")
        if self.link is not None:
            self.link_state.emit(f"{self.link.state.value}: {text}")

    def _on_link_auth(self, state: str, failure: str | None) -> None:
        self.record_event("link_auth", state=state, failure=failure)
        if failure:
            self.message.emit(f"the robot cannot be moved: {failure}")

    def record_event(self, kind: str, **detail) -> None:
        """An operator action or a link change worth keeping in a recording."""
        self.event.emit(kind, detail)

    def observe_sample(self, sample: TimedSample) -> None:
        """A joint sample from the link (its reader thread hands it here through ``call_soon``)."""
        self.last_sample_s = time.monotonic()
        q = self.link.joint_map.to_model(sample.joints_deg) if self.link is not None else self.cell.joint_map.to_model(sample.joints_deg)
        restarts = self.controller_clock.restarts
        t_sent = self.controller_clock.stamp(sample.t_host_s, sample.sample.t_ms / 1000.0)
        if self.controller_clock.restarts != restarts:
            self.observations.live_history.forget(sample.t_host_s)  # a restarted controller: nothing before vouches for now
        self.observations.live_history.add(t_sent, q)
        if self.motion.motion is Motion.UNKNOWN:
            pending = self._pending_move
            if pending is not None and not pending[1].finished:
                self._set_motion(MotionState(Motion.MOVING, pending[0], "the link is back"))
            else:
                self._set_motion(MotionState(Motion.IDLE, self.motion.what, "the link is back: the robot stands where its joints say"))
        self.sample_received.emit(sample, q)
        if self.replaying:
            return  # the recorded joints drive the views while a recording is replayed
        self._show_joints(q)

    def show_replayed_joints(self, joints_deg) -> None:
        """Joints from a recording being replayed: the CAD views follow them, the robot does not move."""
        self._show_joints(np.array(joints_deg, dtype=float))

    def _show_joints(self, q: np.ndarray) -> None:
        # Emitted only on a change: a still robot streams the same joints 50 times a second, and every
        # pane would redraw (or filter the repeats itself).
        changed = q.shape != np.shape(self.joints_deg) or not np.array_equal(q, self.joints_deg)
        self.joints_deg = q
        if changed:
            self.joints_changed.emit(self.joints_deg)

    @property
    def link_up(self) -> bool:
        return self.link is not None and self.link.state is LinkState.UP

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

    def _judge(self, estimate) -> ResultVerdict:
        tolerance = self.task.tolerance_mm if self.task is not None else None
        return judge(estimate, self.workcell.safety, tolerance) if tolerance is not None else judge(estimate, self.workcell.safety)

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

    def apply_hand_eye_file(self, path) -> None:
        """Use a measured camera mounting in place of the model's: ``videocal calibrate-hand-eye`` output, easy_handeye2's
        ``.calib``, or a ``static_transform_publisher`` launch file (MoveIt 2's hand-eye result) on any frame of the arm
        fixed to the flange's link (``tool0`` for a cell whose flange is ``flange``)."""
        from calib_core.vision.hand_eye_io import load_mounting

        cam2frame, frame = load_mounting(path)
        self.apply_cam2flange(self.robot.on_flange(cam2frame, frame, str(path)), f"camera mounting from {path}")

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

    def board_view_plan(self, spec, n: int = 16) -> list[np.ndarray]:
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
        rec = self.recorder
        self.stop_recording()
        if rec is not None:
            rec.wait_finished(5.0)  # a file finishing in the background is not cut off by the exit
        if self.link is not None:
            self.link.close()
        if self.site is not None:
            self.site.close()
