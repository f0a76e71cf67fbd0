"""The operator core's replay (``core.replay``): a recording, or a ROS 2 bag, played back in place of the live camera.

At a position on the recording's time axis, the frame recorded then is what picks are made on (through the frames'
replay history), the CAD views follow the recorded joints, and the point pairs and the last solve appear as they
stood. The first edit the operator makes (a pick, a delete, a solve...) branches a new session from that instant: the
pairs stop following the recording and the operator works on the recorded frames. The file is only ever read. While it
plays, the cell uses the intrinsics the recording was made with; closing gives the live camera's back, and the live
session as it was unless it was branched.

A part of :class:`~calib_core.operator.core.OperatorCore`, given the cell, the session, the frames, the arm (which
shows the recorded joints without moving the robot) and the log. The window's replay bar is its view and its clock.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from psygnal import Signal

from calib_core.calibration.look_solving import show_solution
from calib_core.bags.bag_playback import BagPlayback, is_bag
from calib_core.calibration.session import CalibrationSession
from calib_core.camera.intrinsics import Intrinsics
from calib_core.connectors.frame import Frame
from calib_core.errors import FileFormatError
from calib_core.link.joint_history import JointHistory
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.frame_holding import FrameHolding
from calib_core.recording.playback import RecordedSolve
from calib_core.ros2.joint_units import user_per_si


class Replaying:
    """``playback`` (a :class:`~calib_core.recording.playback.RecordingPlayback` or a bag's, ``None`` when nothing
    is replayed), ``path``, ``position_s`` (s from its start), ``branched_at_s`` (``None`` until the first edit),
    ``complete`` and ``problem`` (a recording cut off by a crash, and why). ``branched(t_s)`` at the first edit.

    Its public members: open, seek, recover, close, the event ``branched`` and the state the replay bar shows (the
    recording, its playback, the position, where it branched, whether it is complete, what is wrong with it)."""

    branched = Signal(float)

    def __init__(self, cell: Cell, session: CalibrationSession, frames: FrameHolding, arm: Arm, log: OperatorLog):
        self._cell, self._session, self._frames, self._arm, self._log = cell, session, frames, arm, log
        self.playback = None
        self.path: Path | None = None
        self.position_s = 0.0
        self.branched_at_s: float | None = None
        self.complete, self.problem = True, None
        self._applying = False
        self._shown_frame: int | None = None
        self._shown_solve: int | None = None
        self._live_state = None
        session.undo.changed.connect(self._on_edit)

    # --- opening and closing -------------------------------------------------------------------
    def open(self, path) -> None:
        """Open a recording or bag (:meth:`seek` shows a position: its start first). Raises :class:`FileFormatError`
        (naming the file and why) and
        changes nothing when it is not a readable one."""
        from calib_core.recording.playback import RecordingPlayback
        from calib_core.recording.reader import read_recording

        path = Path(path)
        if is_bag(path):  # a ROS 2 bag: its frames, with the arm's joints at each frame's stamp
            robot = self._cell.robot
            playback, complete, problem = (
                BagPlayback(path, robot.joint_names, user_per_si(robot.joint_units)),
                True,
                None,
            )
            if not len(playback.frames):
                playback.close()
                raise FileFormatError(path, f"no image on {playback.frames.topic}")
        else:
            contents = read_recording(path)
            if not contents.messages:
                raise FileFormatError(path, "the recording holds no messages")
            playback, complete, problem = RecordingPlayback(contents, path.name), contents.complete, contents.problem
        recorded_intrinsics = None
        if playback.setup.get("intrinsics"):
            try:
                recorded_intrinsics = Intrinsics.from_dict(playback.setup["intrinsics"])
            except (KeyError, TypeError, ValueError) as exc:
                getattr(playback, "close", lambda: None)()
                raise FileFormatError(path, f"its intrinsics cannot be read ({exc})", "/videocal/setup") from None
        self._close_playback()
        if self.playback is None:
            s = self._session
            self._live_state = (s.pairs.pairs(), s.result.solved, self._cell.intrinsics)
        # Picks and solves on the recorded frames need the camera they were recorded with.
        if recorded_intrinsics is not None:
            self._cell.use_intrinsics(recorded_intrinsics)
        self.playback, self.path, self.complete, self.problem = playback, path, complete, problem
        history = JointHistory.from_arrays(
            playback.joint_times_s,
            playback.joints_deg,
            self._cell.workcell.safety.settle_rule,
            self._cell.robot.joint_names,
        )
        self._frames.begin_replay(history, path.name)
        self.branched_at_s = None
        self.position_s = 0.0
        self._shown_frame = self._shown_solve = None
        self._as_replay(self._session.undo.clear)  # clearing the live session's undo history is not an operator edit
        note = "" if complete else f" - cut off: {problem}; Recover... writes a complete copy"
        if isinstance(playback, BagPlayback):
            joints = (
                f"joints from {playback.joint_topic}"
                if playback.joint_topic
                else "no joint states: a camera alone, nothing robot-bound"
            )
            note = f" (ROS 2 bag, {playback.frames.topic}; {joints})"
        self._log.say(
            f"replaying {path.name}: {playback.duration_s:.1f} s, {len(playback.frames)} frames, "
            f"{len(playback.solves)} solves{note}"
        )

    def close(self) -> bool:
        """Back to the live camera: its intrinsics, and the live session as it was unless the replay was branched
        (then the branched session stays). Returns whether it was branched; nothing to close: ``False``."""
        if self.playback is None:
            return False
        branched = self.branched_at_s is not None
        if self._live_state is not None:
            self._cell.use_intrinsics(self._live_state[2])  # the live camera's, whatever the recording used
        if not branched and self._live_state is not None:
            pairs, result, _ = self._live_state

            def restore():
                self._session.pairs.replace_all(pairs)
                self._session.result.show(result)
                self._session.undo.clear()

            self._as_replay(restore)
        self._close_playback()
        self.playback = self.path = self._live_state = None
        self._frames.end_replay()
        self._log.say(
            "replay closed: "
            + ("the branched session stays open" if branched else "the live session is back as it was")
        )
        return branched

    def _close_playback(self) -> None:
        close = getattr(self.playback, "close", None)  # a bag keeps its file open while it is replayed
        if close is not None:
            close()

    def release_file(self) -> None:
        """Let go of the file being replayed (the window closes); nothing else changes."""
        self._close_playback()

    def recover(self) -> Path | None:
        """Write a complete copy of a cut-off recording beside it (every message before the cut); its path."""
        from calib_core.recording.reader import recover

        if self.path is None:
            return None
        out = self.path.with_name(self.path.stem + "-recovered.mcap")
        contents = recover(self.path, out)
        self._log.say(f"recovered {len(contents.messages)} messages into {out}")
        return out

    # --- the position --------------------------------------------------------------------------
    def seek(self, t_s: float) -> Frame | None:
        """Go to ``t_s`` (s from the start, clipped to the recording): the recorded joints are shown, the pairs and
        solve as they stood then (until branched). Returns the frame recorded then when it is another than the one
        last returned (on the recording's time axis, the clock of its joint history), else ``None``."""
        pb = self.playback
        if pb is None:
            return None
        t_s = min(max(0.0, t_s), pb.duration_s)
        self.position_s = t_s
        frame = None
        k = pb.frame_index_at(t_s)
        if k is not None and k != self._shown_frame:
            image = pb.frames.image(k)
            if image is not None:
                self._shown_frame = k
                frame = Frame(image, k, float(pb.frames.times_s[k]), float(pb.frames.times_s[k]))
        q = pb.joints_at(t_s)
        if q is not None:
            self._arm.show_joints(q)
        if self.branched_at_s is None:
            self._as_replay(lambda: self._apply_session(t_s))
        return frame

    def state_text(self) -> str:
        """Where the replay stands, in words: branched, or how many pairs and solves so far."""
        pb = self.playback
        if pb is None:
            return ""
        if self.branched_at_s is not None:
            return f"branched at {self.branched_at_s:.1f} s"
        return (
            f"{len(self._session.pairs)} pairs, {sum(1 for s in pb.solves if s.t_s <= self.position_s)} solves so far"
        )

    def _apply_session(self, t_s: float) -> None:
        pb, s = self.playback, self._session
        pairs = pb.pairs_at(t_s)
        if pairs != s.pairs.pairs():
            s.pairs.replace_all(pairs)
        solve = pb.solve_at(t_s)
        if solve is None and self._shown_solve is not None:
            s.result.clear()
        elif solve is not None and solve.id != self._shown_solve:
            self._show_solve(solve)
        self._shown_solve = None if solve is None else solve.id

    def _show_solve(self, solve: RecordedSolve) -> None:
        from calib_core.recording.replay import solve_from_inputs

        c = solve.context
        if not c:
            self._log.say(
                f"solve {solve.id} was recorded without its robot context: its camera pose only is in the file"
            )
            return
        solution = solve_from_inputs(solve.inputs)  # deterministic: the same answer as recorded
        numbers = [p.number for p in self._session.pairs.usable()]
        obj2world, cam_model, tcp_model = (
            np.asarray(c[k], dtype=float) for k in ("obj2world", "cam2world_model", "tcp2base_model")
        )
        show_solution(
            self._session,
            solution,
            obj2world,
            cam_model,
            tcp_model,
            c.get("joints_deg"),
            numbers,
            points_obj_mm=solve.inputs.get("points_3d"),
            intrinsics=Intrinsics.from_dict(solve.inputs["intrinsics"]),
        )

    # --- branching -----------------------------------------------------------------------------
    def _as_replay(self, change) -> None:
        """Make ``change`` to the session as the replay, not as an operator's edit."""
        self._applying = True
        try:
            change()
        finally:
            self._applying = False

    def _on_edit(self) -> None:
        if self.playback is None or self._applying or self.branched_at_s is not None:
            return
        self.branched_at_s = self.position_s
        self.branched.emit(self.position_s)
        self._log.say(
            f"new session branched from {self.path.name} at {self.position_s:.1f} s; the recording is not changed"
        )
