"""The window's state and its connections to the world, without widgets: the workcell and
robot, the calibration session, the controller link (with its simulator), the camera.

Panes read from here and send the operator's actions here; nothing here draws.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, Signal

from calib_core.calibration.session import CalibrationError, CalibrationSession
from calib_core.camera.intrinsics import Intrinsics
from calib_core.link.driver import ControllerLink
from calib_core.link.link_types import LinkState
from calib_core.robot import solve_ik
from calib_core.testbed.test_bed import TestBed
from calib_core.workcell import TaskLocation


def spawn_simulator(joints_deg, folder: Path) -> tuple[subprocess.Popen, Path]:
    """Start the controller simulator on a pty behind a symlink in ``folder``; returns at once."""
    link_path = Path(folder) / "controller"
    q = ",".join(f"{v:.4f}" for v in joints_deg)
    process = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", "sim-controller", "--pty", "--link", str(link_path), "--joints", q],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=str(Path(__file__).resolve().parents[2]),
    )
    return process, link_path


class Workbench(QObject):
    """Signals: ``joints_changed(q)``, ``link_state(str)``, ``message(str)`` (status bar),
    ``error(str)`` (shown to the operator), ``solved()``, ``task_changed(str)``."""

    joints_changed = Signal(object)
    link_state = Signal(str)
    message = Signal(str)
    error = Signal(str)
    solved = Signal()
    task_changed = Signal(str)
    camera_model_changed = Signal()  # the intrinsics or the camera mounting were replaced
    scene_changed = Signal()  # something was put up in the cell or taken down (the calibration board)
    _sample_arrived = Signal(object)
    _state_arrived = Signal(str, str)

    def __init__(self, bed: TestBed | None = None, parent=None):
        super().__init__(parent)
        self.bed = bed or TestBed.create()
        self.workcell = self.bed.workcell
        self.robot = self.bed.model_robot
        self.intrinsics: Intrinsics = self.bed.intrinsics
        self.session = CalibrationSession()
        self.joints_deg = np.array(self.workcell.home_joints_deg, dtype=float)
        self.task: TaskLocation | None = next(iter(self.workcell.task_locations.values()), None)
        if self.task is not None and self.task.component:
            self.session.set_target(self.task.component)
        self.link: ControllerLink | None = None
        self._sim_process: subprocess.Popen | None = None
        self._tmp = tempfile.TemporaryDirectory(prefix="videocal-")
        self.recorder = None
        self.replaying = False
        self.last_sample_s: float | None = None
        self.session.pairs.subscribe(self._record_pairs_event)
        self._sample_arrived.connect(self._on_sample)
        self._state_arrived.connect(self._on_state_arrived)

    # --- robot and link ----------------------------------------------------------------------
    def start_simulated_controller(self, started: tuple[subprocess.Popen, Path] | None = None) -> str:
        """Start ``videocal sim-controller`` on a pty as a child process (or adopt one already started
        with :func:`spawn_simulator`, so its start-up overlaps the window's) and connect to it."""
        process, link_path = started or spawn_simulator(self.joints_deg, Path(self._tmp.name))
        self._sim_process = process
        device = process.stdout.readline().strip()
        if not device:
            raise RuntimeError("the controller simulator did not start")
        self.connect_link(str(link_path))
        return device

    def connect_link(self, url: str, rate_hz: float = 50.0) -> None:
        if self.link is not None:
            self.link.close()
        self.link = ControllerLink(url, mode="stream", rate_hz=rate_hz)
        self.link.on_sample(self._sample_arrived.emit)  # queued into the GUI thread
        self.link.on_state(lambda state, why: self._state_arrived.emit(state.value, why))
        self.link.start()
        self.message.emit(f"controller link: {url}")

    def _on_state_arrived(self, state: str, why: str) -> None:
        self.record_event("link_state", state=state, why=why)
        self.link_state.emit(f"{state}: {why}")

    def record_event(self, kind: str, **detail) -> None:
        """An event for the recording, when one is running (link states, accepts, candidate choices)."""
        if self.recorder is not None:
            self.recorder.record_event(kind, **detail)

    def _on_sample(self, sample) -> None:
        self.last_sample_s = time.monotonic()
        if self.recorder is not None:
            self.recorder.record_joints(sample.sample.seq, sample.sample.t_ms, sample.t_host_s, sample.joints_deg)
        if self.replaying:
            return  # the recorded joints drive the views while a recording is replayed
        self.joints_deg = np.array(sample.joints_deg, dtype=float)
        self.bed.joints_deg = self.joints_deg.copy()  # the simulated camera follows the commanded joints
        self.joints_changed.emit(self.joints_deg)

    def show_replayed_joints(self, joints_deg) -> None:
        """Joints from a recording being replayed: the CAD views follow them, the robot does not move."""
        self.joints_deg = np.array(joints_deg, dtype=float)
        self.joints_changed.emit(self.joints_deg)

    @property
    def link_up(self) -> bool:
        return self.link is not None and self.link.state is LinkState.UP

    def move_to(self, target2base: np.ndarray, what: str, *, wait: bool = False, timeout_s: float = 30.0):
        """IK for the target from the current joints, then MVJ over the link."""
        q = solve_ik(self.robot, target2base, self.joints_deg).q_deg
        return self.move_joints(q, what, wait=wait, timeout_s=timeout_s)

    def move_joints(self, q, what: str, *, wait: bool = False, timeout_s: float = 30.0):
        """MVJ to joints ``q`` (deg) over the link."""
        if self.replaying:
            raise CalibrationError("a recording is being replayed: the views show it, not the robot; close the replay before moving the robot")
        if self.link is None:
            raise CalibrationError("no controller link: connect one first")
        handle = self.link.move_joints(q, timeout_s=timeout_s)
        if handle.finished:
            handle.wait(0)  # finished before it started: nothing was sent, and this raises the link's reason
        self.message.emit(f"moving to {what}: joints {', '.join(f'{v:.1f}' for v in q)} deg")
        if wait:
            handle.wait(timeout_s)
        return handle

    def go_to_task(self, *, approach: bool = True, corrected: bool = False, wait: bool = False):
        if self.task is None:
            raise CalibrationError("choose a task location first")
        target = self.task.approach2base if approach else self.task.tcp2base
        if corrected:
            if self.session.corrections.latest(self.task.name) is None:
                raise CalibrationError(f"no stored correction for {self.task.name}: calibrate and store one first")
            target = self.session.corrections.corrected_target(self.task.name, target)
        what = f"{self.task.name} ({'approach' if approach else 'task'}{', corrected' if corrected else ''})"
        return self.move_to(target, what, wait=wait)

    def set_task_approach(self, name: str, approach_mm: float) -> None:
        """Edit a task location's approach distance (mm): an undoable edit."""
        from calib_core.calibration.commands import SetTaskApproach

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
        self.task_changed.emit(name)

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
        result = self.session.calibrate(self.intrinsics, obj2world, self.model_cam2world(), self.model_tcp2base(), self.joints_deg)
        if self.recorder is not None:
            context = {"obj2world": obj2world, "cam2world_model": result.cam2world_model, "tcp2base_model": result.tcp2base_model, "joints_deg": self.joints_deg, "target": target}
            self.recorder.record_solve(self.session.last_solve_inputs, result.solution.to_dict(), context=context)
        self.solved.emit()
        return result

    def store_correction(self):
        if self.task is None:
            raise CalibrationError("choose the task location the correction is for")
        c = self.session.store_correction(self.task.name)
        if self.recorder is not None:
            self.recorder.record_correction({"task": c.task, "displacement_mm": c.displacement_mm, "rotation_deg": c.rotation_deg, "std_displacement_mm": c.std_displacement_mm, "std_rotation_deg": c.std_rotation_deg, "joints_deg": c.joints_deg, "rms_px": c.rms_px, "pairs": c.pairs})
        self.message.emit(f"correction stored for {self.task.name}: {np.linalg.norm(c.displacement_mm):.2f} mm, {np.linalg.norm(c.rotation_deg):.3f} deg")
        return c

    def apply_hand_eye_file(self, path) -> None:
        """Use a measured camera mounting (``videocal calibrate-hand-eye`` output) in place of the model's."""
        from calib_core.vision.hand_eye_io import load_cam2flange

        cam2flange = load_cam2flange(path)
        self.apply_cam2flange(cam2flange, f"camera mounting from {path}")

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
        self.intrinsics = intrinsics
        self.camera_model_changed.emit()
        self.message.emit(why)

    # --- the calibration board (simulated cell) ---------------------------------------------------
    def show_calibration_board(self, spec, on: bool = True) -> np.ndarray:
        """Put a ChArUco board up in the simulated cell (upright, facing the robot), or take it down.
        Returns its ``board2base`` (4, 4) mm."""
        from calib_core.vision.board import board_item
        from calib_core.vision.hand_eye_sim import board_facing_robot

        board2base = board_facing_robot(spec)
        self.bed.extra_items = [board_item(spec, board2base)] if on else []
        self.scene_changed.emit()
        return board2base

    def board_view_plan(self, spec, n: int = 12) -> list[np.ndarray]:
        """Joint vectors (deg) from which the modelled camera sees the board from different directions."""
        from calib_core.vision.hand_eye_sim import board_facing_robot, hand_eye_poses

        return hand_eye_poses(self.bed, spec, board_facing_robot(spec), n)

    # --- workspace and recording --------------------------------------------------------------
    def workspace(self):
        from calib_core.workspace.workspace import Workspace

        return Workspace(str(self.workcell.path), self.intrinsics, dict(self.workcell.task_locations), self.session.target, self.session.pairs.pairs(), self.session.corrections)

    def save_workspace(self, path) -> None:
        from calib_core.workspace.workspace import save_workspace

        save_workspace(path, self.workspace())
        self.message.emit(f"workspace saved to {path}")

    def open_workspace(self, path) -> None:
        """Load pairs, corrections and task locations; the current ones stay if the file is bad."""
        from calib_core.workspace.workspace import load_workspace

        ws = load_workspace(path)  # raises before anything is changed
        self.workcell.task_locations.update(ws.task_locations)
        if ws.target:
            self.session.set_target(ws.target)
        self.session.pairs.replace_all(ws.pairs)
        self.session.pairs._next_number = max([p.number for p in ws.pairs], default=0) + 1
        for task in self.session.corrections.tasks():
            while self.session.corrections.latest(task) is not None:
                self.session.corrections.remove_last(task)
        for task in ws.corrections.tasks():
            for c in ws.corrections.history(task):
                self.session.corrections.add(c)
        self.session.undo.clear()
        self.message.emit(f"workspace {path} opened: {len(ws.pairs)} pairs, {len(ws.corrections.tasks())} corrected locations")

    def start_recording(self, path) -> None:
        from calib_core.recording.recorder import SessionRecorder

        self.stop_recording()
        self.recorder = SessionRecorder(path)
        self.recorder.record_setup(workcell=str(self.workcell.path), intrinsics=self.intrinsics.to_dict(), target=self.session.target, task=None if self.task is None else self.task.name)
        self.message.emit(f"recording to {path}")

    def stop_recording(self) -> None:
        rec = getattr(self, "recorder", None)
        if rec is not None:
            rec.close()
            self.message.emit(f"recording {rec.path} closed ({rec.messages} messages)")
        self.recorder = None

    def record_frame(self, frame) -> None:
        if self.recorder is not None:
            self.recorder.record_frame(frame.image, frame.t_host_s)

    def _record_pairs_event(self, event: str, number) -> None:
        if self.recorder is None:
            return
        from calib_core.recording.playback import pair_to_dict

        detail = {"number": number}
        if number is not None and event in ("added", "changed"):
            detail.update(pair_to_dict(self.session.pairs.get(number)))
        elif event == "reset":  # a whole new set (clear, undo of a clear, a workspace): keep it all
            detail["pairs"] = [pair_to_dict(p) for p in self.session.pairs]
        self.record_event(f"pair_{event}", **detail)

    def close(self) -> None:
        self.stop_recording()
        if self.link is not None:
            self.link.close()
        if self._sim_process is not None and self._sim_process.poll() is None:
            self._sim_process.terminate()
            try:
                self._sim_process.wait(timeout=3)
            except subprocess.TimeoutExpired:
                self._sim_process.kill()
            self._sim_process.stdout.close()
        self._tmp.cleanup()
