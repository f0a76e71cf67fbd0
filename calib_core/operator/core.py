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

from collections.abc import Callable

import numpy as np
from psygnal import Signal

from calib_core.calibration.look_result import ChooseCandidate
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import concat, invert
from calib_core.link.joint_history import JointHistory
from calib_core.operator.arm import Arm
from calib_core.operator.camera_calibrating import CameraCalibrating
from calib_core.operator.cell import Cell
from calib_core.operator.cell_editor import CellEditor
from calib_core.operator.correction_desk import CorrectionDesk
from calib_core.operator.motion import MotionState
from calib_core.operator.moves import Moves
from calib_core.operator.observations import Observations
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.frame_holding import FrameHolding
from calib_core.operator.pick_refining import PickRefining
from calib_core.operator.picking import Picking
from calib_core.operator.recording_tap import RecordingTap
from calib_core.operator.replaying import Replaying
from calib_core.operator.point_finding import PointFinding
from calib_core.operator.robot_calibrating import RobotCalibrating
from calib_core.operator.workspace_files import WorkspaceFiles
from calib_core.operator.session_recording import SessionRecording
from calib_core.operator.site import Site
from calib_core.operator.task_choice import TaskChoice
from calib_core.operator.tool_measuring import ToolMeasuring
from calib_core.workcell import TaskLocation


class OperatorCore:
    """The program's assembly: the parts, each given what it needs: :attr:`cell` (with its events
    ``camera_model_changed()``, ``scene_changed()``), :attr:`session` (pairs, options, result, corrections, the one
    undo stack), :attr:`tasks` (the task location worked at), :attr:`observations` (frames, the held one),
    :attr:`frames` (which frame a pick is made on), :attr:`refining` (a click moved onto its feature),
    :attr:`arm` (joints, link, moves, Stop), :attr:`picking` (*Point*, *Accept*, *Calibrate*),
    :attr:`finder` (*Find points*), :attr:`moves` (moves by name), :attr:`robot_calibration` (and the
    measured tool in use), :attr:`tool` (grasps, *Measure tool*), :attr:`desk` (store, *Verify*),
    :attr:`recording`, :attr:`vision` (the camera's calibration), :attr:`replay`, :attr:`files` (workspace,
    exports), :attr:`editor` (edits of the cell) and :attr:`log` (``message(text)``, ``event(kind, detail)``).

    Event (psygnal): ``solved()`` after *Calibrate* or *Calibrate on edges*; every other event is its part's own.

    Its public members are many for a reason: twenty are the parts it assembles; eight read the state the
    workflow asks for most (the task, the cell's workcell, robot and intrinsics, the arm's link, joints, motion and
    link state); the rest are the few actions that span parts (connect the site's controller, choose a task,
    undo and redo with the pair being made let go, choose a solution, a mounting from a file, close)."""

    solved = Signal()

    def __init__(self, cell: Cell, site: Site | None = None, *, call_soon: Callable[..., None] | None = None):
        self.cell = cell
        self.site = site
        self._call_soon = call_soon or (lambda fn, *args: fn(*args))
        self.log = OperatorLog()
        self.session = CalibrationSession()
        self.tasks = TaskChoice(cell.workcell)
        self.tasks.changed.connect(self._task_chosen)  # first: the session's target and verdict follow before any view
        if self.task is not None and self.task.component:
            self.session.set_target(self.task.component)
        self.revision = 0
        """Counts the changes of what a workspace holds (pairs, results, corrections, task locations, the
        target): the autosave writes only when it moved."""
        for signal in (
            self.session.pairs.changed,
            self.session.corrections.changed,
            self.session.undo.changed,
            self.session.result.changed,
            self.session.target_changed,
            self.tasks.changed,
        ):
            signal.connect(self._count_change)
        self.observations = Observations(
            JointHistory(rule=self.workcell.safety.settle_rule, joint_names=self.robot.joint_names)
        )
        """The frames (live, or a recording's while it is replayed), the held one, and the joint history
        that stamps them."""
        self.arm = Arm(cell, self.observations, call_soon=self._call_soon)
        """The robot behind the link: its joints, its moves and how the last one stands, Stop."""
        self.arm.message.connect(self.log.say)
        self.arm.event.connect(self.log.event.emit)
        self.frames = FrameHolding(self.observations, self.arm, self.session.pairs, self.log)
        self.refining = PickRefining(cell, self.session, self.frames, self.arm)
        self.picking = Picking(cell, self.session, self.frames, self.refining, self.arm, self.log)
        self.finder = PointFinding(cell, self.session, self.picking, self.frames, self.refining, self.log)
        self.moves = Moves(cell, self.session, self.tasks, self.arm)
        self.robot_calibration = RobotCalibrating(cell, self.session, self.arm, self.log)
        self.recording = SessionRecording(lambda recorder: RecordingTap(self, recorder), self.log)
        """The session's recording: start, stop, the recorder writing now."""
        self.tool = ToolMeasuring(
            cell, self.tasks, self.arm, self.frames, self.finder, self.robot_calibration, self.log
        )
        self.desk = CorrectionDesk(
            cell, self.session, self.tasks, self.arm, self.picking, self.robot_calibration, self.log
        )
        self.vision = CameraCalibrating(cell, self.frames, self.observations, self.arm, self.log)
        self.vision.board_put_up.connect(self._put_up_on_site)
        """The camera's calibration: board views, intrinsics and mounting, the board in the cell."""
        self.replay = Replaying(cell, self.session, self.frames, self.arm, self.log)
        """A recording or bag played back in place of the live camera."""
        self.files = WorkspaceFiles(cell, self.session, self.log)
        self.editor = CellEditor(cell, self.session, self.tasks, self.arm, self.log)
        """Edits of the cell (components, features, task locations), undoable, saved back to its file."""
        for signal in (self.picking.solved, self.finder.solved):
            signal.connect(self.solved.emit)
        self._judge_by_the_task()

    @property
    def task(self) -> TaskLocation | None:
        """The task location worked at (:attr:`tasks`' choice)."""
        return self.tasks.task

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
            self._connect_link(url, options=getattr(self.site, "controller_options", None))
        return url

    def _connect_link(self, url: str, rate_hz: float = 50.0, options: dict | None = None) -> None:
        """Open the controller connector registered for ``url``'s scheme and start it."""
        link = self.arm.connect(url, rate_hz, options)
        if self.site is not None:
            self.site.attach(link)
        link.start()
        self.log.say(f"controller link: {url}")
        if getattr(
            link, "publishes_transforms", False
        ):  # declared by the connector (ROS 2: the results on /tf_static too)
            for signal in (self.cell.camera_model_changed, self.desk.correction_stored):
                signal.connect(self._publish_static_transforms, unique=True)
            self._publish_static_transforms()

    # The arm's state, read where the workflow needs it (the arm alone changes it).
    @property
    def link(self):
        return self.arm.link

    @property
    def joints_deg(self) -> np.ndarray:
        return self.arm.joints_deg

    @property
    def motion(self) -> MotionState:
        return self.arm.state

    @property
    def link_up(self) -> bool:
        return self.arm.link_up

    def _static_transforms(self) -> list[tuple[str, str, np.ndarray]]:
        """What the cell's ROS side is told: ``(parent, child, child2parent_mm)`` for the camera mounting in use
        (the site's ``camera_frame`` on its ``camera_parent_frame``, :func:`~calib_core.ros2.frame_names.camera_frames`:
        by default ``videocal_camera_optical_frame`` on the flange; z along the optical axis, x right, y down: ROS's
        optical frame) and each task's corrected target (``videocal/<task>`` in the base frame; the correction, or the
        plan if none)."""
        from calib_core.ros2.frame_names import camera_frames

        frames = self.workcell.robot_spec.frames
        base = str(frames.get("base") or "base_link")
        parent, child = camera_frames(self.workcell, flange_frame=self.robot.roles.get("flange"))
        q = self.joints_deg
        out = [(parent, child, concat(self.robot.fk(q, "camera"), invert(self.robot.fk(q, parent))))]
        for name, task in self.workcell.task_locations.items():
            out.append((base, f"videocal/{name}", self.session.corrections.corrected_target(name, task.tcp2base)))
        return out

    def _publish_static_transforms(self, *_) -> None:
        link = self.link
        if link is None or not getattr(link, "publishes_transforms", False):
            return
        try:
            link.publish_static_transforms(self._static_transforms())
        except Exception as exc:  # the ROS side is an output: its failure must not stop the calibration
            self.log.say(f"could not publish /tf_static: {exc}")

    def _put_up_on_site(self, extras: list) -> None:
        if self.site is not None:
            self.site.put_up(extras)

    def set_task(self, name: str) -> None:
        """Work at task location ``name``: its component becomes the target."""
        self.tasks.choose(name)

    def _task_chosen(self, name: str) -> None:
        task = self.task
        if task is None:
            self._judge_by_the_task()  # the chosen task location was removed: the default tolerance
        elif task.name == name:
            if task.component and task.component != self.session.target:
                self.session.set_target(task.component)
            self._judge_by_the_task()  # the task's tolerance is part of the verdict

    def _judge_by_the_task(self) -> None:
        self.session.result.judge_by(self.workcell.safety, self.task.tolerance_mm if self.task is not None else None)

    def undo(self) -> str | None:
        """Undo the last edit (its label, None if there was none); the pair being made is let go."""
        self.picking.let_go()
        return self.session.undo.undo()

    def redo(self) -> str | None:
        return self.session.undo.redo()

    def choose_candidate(self, index: int) -> None:
        """Take solution ``index`` of an ambiguous solve (undoable)."""
        self.session.undo.push(ChooseCandidate(self.session.result, index))
        self.log.record("candidate_chosen", index=index, solution=index + 1)

    # --- frames of reference -------------------------------------------------------------------
    def model_cam2world(self) -> np.ndarray:
        return self.robot.fk(self.joints_deg, "camera")

    # --- the camera model ------------------------------------------------------------------------
    def apply_hand_eye_file(self, path) -> None:
        """Use a measured camera mounting in place of the model's: ``videocal calibrate-hand-eye`` output,
        easy_handeye2's
        ``.calib``, or a ``static_transform_publisher`` launch file (MoveIt 2's hand-eye result) on any frame of the arm
        fixed to the flange's link (``tool0`` for a cell whose flange is ``flange``)."""
        from calib_core.vision.hand_eye_io import load_mounting

        cam2frame, frame = load_mounting(path)
        self.vision.apply_cam2flange(self.robot.on_flange(cam2frame, frame, str(path)), f"camera mounting from {path}")

    def close(self) -> None:
        self.recording.close(wait_s=5.0)  # a file finishing in the background is not cut off by the exit
        self.arm.close()
        self.files.release()  # the workspace file is free for another window
        if self.site is not None:
            self.site.close()
