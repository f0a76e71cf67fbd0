"""The replay timeline: a recording, or a ROS 2 bag, played back in the window.

The camera pane shows the recorded frames, the CAD views follow the recorded joints, and the point
pairs and the last solve appear as they stood at the timeline's position. The first edit the
operator makes (a pick, a delete, a solve...) branches a new session from that instant: the pairs
stop following the recording and the operator works on the recorded frames. The recording file is
only ever read. While it plays, the window uses the intrinsics the recording was made with. Closing the
replay gives the live camera's intrinsics back, and the live session as it was unless it was branched.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QPushButton, QSlider, QStyle, QToolButton, QWidget

from calib_core.bags.bag_playback import BagPlayback, is_bag
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import FileFormatError
from calib_core.link.joint_history import JointHistory
from calib_core.recording.playback import RecordedSolve, RecordingPlayback
from calib_core.recording.reader import read_recording, recover
from calib_core.recording.replay import solve_from_inputs
from calib_core.ros2.joint_units import user_per_si
from calib_core.connectors.frame import Frame

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0)


class ReplayBar(QWidget):
    """Play, pause and scrub a recording. ``show_frame(Frame)`` puts a frame on the camera pane;
    ``closed`` is emitted when the operator closes the replay."""

    closed = Signal()

    def __init__(self, workbench, show_frame: Callable[[Frame], None], parent=None):
        super().__init__(parent)
        self.workbench = workbench
        self._show_frame = show_frame
        self.playback: RecordingPlayback | None = None
        self.path: Path | None = None
        self.position_s = 0.0
        self.branched_at_s: float | None = None
        self._applying = False
        self._shown_frame: int | None = None
        self._shown_solve: int | None = None
        self._live_state = None
        self._last_tick = 0.0

        self.play_button = QToolButton()
        self.play_button.setObjectName("replay_play")
        self.play_button.setToolTip("Play or pause the recording (Space)")
        self.play_button.clicked.connect(self.toggle_play)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setObjectName("replay_slider")
        self.slider.setToolTip("Scrub through the recording")
        self.slider.valueChanged.connect(self._slider_moved)
        self.time_label = QLabel("0.0 / 0.0 s")
        self.time_label.setMinimumWidth(110)
        self.speed = QComboBox()
        self.speed.setToolTip("Playback speed")
        for s in SPEEDS:
            self.speed.addItem(f"{s:g}x", s)
        self.speed.setCurrentIndex(SPEEDS.index(1.0))
        self.state_label = QLabel("")
        self.state_label.setWordWrap(False)
        self.recover_button = QPushButton("Recover...")
        self.recover_button.setToolTip(
            "Write a complete copy of this cut-off recording, with every message before the cut"
        )
        self.recover_button.clicked.connect(self._recover)
        self.recover_button.hide()
        self.close_button = QPushButton("Close replay")
        self.close_button.setToolTip("Back to the live camera and robot")
        self.close_button.clicked.connect(self.close_replay)
        row = QHBoxLayout(self)
        row.setContentsMargins(4, 2, 4, 2)
        row.addWidget(QLabel("<b>Replay</b>"))
        row.addWidget(self.play_button)
        row.addWidget(self.slider, 1)
        row.addWidget(self.time_label)
        row.addWidget(self.speed)
        row.addWidget(self.state_label)
        row.addWidget(self.recover_button)
        row.addWidget(self.close_button)
        self._timer = QTimer(self)
        self._timer.setInterval(33)
        self._timer.timeout.connect(self._tick)
        self._set_play_icon()
        workbench.session.undo.changed.connect(self._on_edit)
        self.hide()

    # --- opening and closing -------------------------------------------------------------------
    def open(self, path) -> None:
        """Open a recording at its start. Raises ``FileFormatError`` (the window says why) and changes
        nothing when the file is not a readable recording."""
        path = Path(path)
        if is_bag(path):  # a ROS 2 bag: its frames, with the arm's joints at each frame's stamp
            robot = self.workbench.robot
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
            s = self.workbench.session
            self._live_state = (s.pairs.pairs(), s.result_snapshot(), self.workbench.intrinsics)
        # Picks and solves on the recorded frames need the camera they were recorded with.
        if recorded_intrinsics is not None:
            self.workbench.cell.use_intrinsics(recorded_intrinsics)
        self.playback, self.path = playback, path
        history = JointHistory.from_arrays(
            playback.joint_times_s,
            playback.joints_deg,
            self.workbench.workcell.safety.settle_rule,
            self.workbench.robot.joint_names,
        )
        self.workbench.picking.begin_replay(history, path.name)
        self.branched_at_s = None
        self._shown_frame = self._shown_solve = None
        self._applying = True  # clearing the live session's undo history is not an operator edit
        try:
            self.workbench.session.undo.clear()
        finally:
            self._applying = False
        self.slider.blockSignals(True)
        self.slider.setRange(0, max(1, int(round(playback.duration_s * 1000))))
        self.slider.setValue(0)
        self.slider.blockSignals(False)
        self.recover_button.setVisible(not complete)
        self.show()
        self.seek(0.0)
        note = "" if complete else f" - cut off: {problem}; Recover... writes a complete copy"
        if isinstance(playback, BagPlayback):
            joints = (
                f"joints from {playback.joint_topic}"
                if playback.joint_topic
                else "no joint states: a camera alone, nothing robot-bound"
            )
            note = f" (ROS 2 bag, {playback.frames.topic}; {joints})"
        self.workbench.message.emit(
            f"replaying {path.name}: {playback.duration_s:.1f} s, {len(playback.frames)} frames, {len(playback.solves)} solves{note}"
        )

    def close_replay(self) -> None:
        if self.playback is None:
            return
        self.pause()
        branched = self.branched_at_s is not None
        if self._live_state is not None:
            self.workbench.cell.use_intrinsics(self._live_state[2])  # the live camera's, whatever the recording used
        if not branched and self._live_state is not None:
            pairs, result, _ = self._live_state
            s = self.workbench.session
            self._applying = True
            try:
                s.pairs.replace_all(pairs)
                s.restore_result(result)
                s.undo.clear()
            finally:
                self._applying = False
        self._close_playback()
        self.playback = self.path = self._live_state = None
        self.workbench.picking.end_replay()
        self.hide()
        self.workbench.message.emit(
            "replay closed: "
            + ("the branched session stays open" if branched else "the live session is back as it was")
        )
        self.closed.emit()

    def _close_playback(self) -> None:
        close = getattr(self.playback, "close", None)  # a bag keeps its file open while it is replayed
        if close is not None:
            close()

    def release_file(self) -> None:
        """Let go of the file being replayed (the window closes); nothing else changes."""
        self._close_playback()

    def _recover(self) -> None:
        if self.path is None:
            return
        out = self.path.with_name(self.path.stem + "-recovered.mcap")
        contents = recover(self.path, out)
        self.recover_button.hide()
        self.workbench.message.emit(f"recovered {len(contents.messages)} messages into {out}")

    # --- playing -------------------------------------------------------------------------------
    @property
    def playing(self) -> bool:
        return self._timer.isActive()

    def play(self) -> None:
        if self.playback is None:
            return
        if self.position_s >= self.playback.duration_s:
            self.seek(0.0)
        self._last_tick = time.monotonic()
        self._timer.start()
        self._set_play_icon()

    def pause(self) -> None:
        self._timer.stop()
        self._set_play_icon()

    def toggle_play(self) -> None:
        if self.playing:
            self.pause()
        else:
            self.play()

    def _set_play_icon(self) -> None:
        icon = QStyle.StandardPixmap.SP_MediaPause if self._timer.isActive() else QStyle.StandardPixmap.SP_MediaPlay
        self.play_button.setIcon(self.style().standardIcon(icon))

    def _tick(self) -> None:
        now = time.monotonic()
        dt, self._last_tick = now - self._last_tick, now
        t = self.position_s + dt * float(self.speed.currentData())
        if t >= self.playback.duration_s:
            t = self.playback.duration_s
            self.pause()
        self.seek(t)

    def _slider_moved(self, value_ms: int) -> None:
        if self.playback is not None:
            self.seek(value_ms / 1000.0)

    def seek(self, t_s: float) -> None:
        """Show the recording as it was at ``t_s`` (s from its start)."""
        pb = self.playback
        if pb is None:
            return
        t_s = min(max(0.0, t_s), pb.duration_s)
        self.position_s = t_s
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(t_s * 1000)))
        self.slider.blockSignals(False)
        self.time_label.setText(f"{t_s:.1f} / {pb.duration_s:.1f} s")
        k = pb.frame_index_at(t_s)
        if k is not None and k != self._shown_frame:
            image = pb.frames.image(k)
            if image is not None:
                self._shown_frame = k
                # on the recording's time axis, the clock of its joint history
                self._show_frame(Frame(image, k, float(pb.frames.times_s[k]), float(pb.frames.times_s[k])))
        q = pb.joints_at(t_s)
        if q is not None:
            self.workbench.show_replayed_joints(q)
        if self.branched_at_s is None:
            self._apply_session(t_s)
        self._update_state()

    def _apply_session(self, t_s: float) -> None:
        pb, s = self.playback, self.workbench.session
        self._applying = True
        try:
            pairs = pb.pairs_at(t_s)
            if pairs != s.pairs.pairs():
                s.pairs.replace_all(pairs)
            solve = pb.solve_at(t_s)
            if solve is None and self._shown_solve is not None:
                s.clear_result()
            elif solve is not None and solve.id != self._shown_solve:
                self._show_solve(solve)
            self._shown_solve = None if solve is None else solve.id
        finally:
            self._applying = False

    def _show_solve(self, solve: RecordedSolve) -> None:
        c = solve.context
        if not c:
            self.workbench.message.emit(
                f"solve {solve.id} was recorded without its robot context: its camera pose only is in the file"
            )
            return
        solution = solve_from_inputs(solve.inputs)  # deterministic: the same answer as recorded
        numbers = [p.number for p in self.workbench.session.pairs.usable()]
        obj2world, cam_model, tcp_model = (
            np.asarray(c[k], dtype=float) for k in ("obj2world", "cam2world_model", "tcp2base_model")
        )
        self.workbench.session.show_result(
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
    def _on_edit(self) -> None:
        if self.playback is None or self._applying or self.branched_at_s is not None:
            return
        self.branched_at_s = self.position_s
        self._update_state()
        self.workbench.message.emit(
            f"new session branched from {self.path.name} at {self.position_s:.1f} s; the recording is not changed"
        )

    def _update_state(self) -> None:
        pb = self.playback
        if pb is None:
            return
        if self.branched_at_s is not None:
            self.state_label.setText(f"<span style='color:#e0a030'>branched at {self.branched_at_s:.1f} s</span>")
        else:
            self.state_label.setText(
                f"{len(self.workbench.session.pairs)} pairs, {sum(1 for s in pb.solves if s.t_s <= self.position_s)} solves so far"
            )
