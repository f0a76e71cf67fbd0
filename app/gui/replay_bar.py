"""The replay timeline: the view and the clock of the core's replay (``core.replay``,
:class:`~calib_core.operator.replaying.Replaying`): play, pause and scrub a recording or a ROS 2 bag; the camera pane
shows the recorded frames, the CAD views follow the recorded joints, the pairs and the last solve appear as they
stood, and the first edit branches a new session (the part says what that means).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QPushButton, QSlider, QStyle, QToolButton, QWidget

from calib_core.connectors.frame import Frame
from calib_core.operator.replaying import Replaying

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0)


class ReplayBar(QWidget):
    """Play, pause and scrub a recording. ``show_frame(Frame)`` puts a frame on the camera pane;
    ``closed`` is emitted when the operator closes the replay."""

    closed = Signal()

    def __init__(self, replay: Replaying, show_frame: Callable[[Frame], None], parent=None):
        super().__init__(parent)
        self.replay = replay
        self._show_frame = show_frame
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
        replay.branched.connect(lambda _t: self._update_state())
        self.hide()

    # --- what the core holds, for the window and tests --------------------------------------------
    @property
    def playback(self):
        return self.replay.playback

    @property
    def path(self):
        return self.replay.path

    @property
    def position_s(self) -> float:
        return self.replay.position_s

    @property
    def branched_at_s(self) -> float | None:
        return self.replay.branched_at_s

    # --- opening and closing -------------------------------------------------------------------
    def open(self, path) -> None:
        """Open a recording at its start. Raises ``FileFormatError`` (the window says why) and changes
        nothing when the file is not a readable recording."""
        self.replay.open(path)
        playback = self.replay.playback
        self.slider.blockSignals(True)
        self.slider.setRange(0, max(1, int(round(playback.duration_s * 1000))))
        self.slider.setValue(0)
        self.slider.blockSignals(False)
        self.recover_button.setVisible(not self.replay.complete)
        self.show()
        self.seek(0.0)

    def close_replay(self) -> None:
        if self.replay.playback is None:
            return
        self.pause()
        self.replay.close()
        self.hide()
        self.closed.emit()

    def release_file(self) -> None:
        """Let go of the file being replayed (the window closes); nothing else changes."""
        self.replay.release_file()

    def _recover(self) -> None:
        if self.replay.recover() is not None:
            self.recover_button.hide()

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
        pb = self.replay.playback
        if pb is None:
            return
        frame = self.replay.seek(t_s)
        t_s = self.replay.position_s
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(t_s * 1000)))
        self.slider.blockSignals(False)
        self.time_label.setText(f"{t_s:.1f} / {pb.duration_s:.1f} s")
        if frame is not None:
            self._show_frame(frame)
        self._update_state()

    def _update_state(self) -> None:
        text = self.replay.state_text()
        if self.replay.branched_at_s is not None:
            text = f"<span style='color:#e0a030'>{text}</span>"
        self.state_label.setText(text)
