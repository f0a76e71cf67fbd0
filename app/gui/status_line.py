"""The status bar's permanent fields: recording, link, camera, pairs; refreshed once a second.

The link shows its state, sample rate, rejected lines and its measured one-way delay (a far controller),
and turns orange when it is up but no joint sample came for ``STALE_LINK_S`` (plus a far link's spread); the camera
shows its frame rate, and turns orange when no
frame came for ``STALE_CAMERA_S`` while live.
"""

from __future__ import annotations

import html
import time
from collections.abc import Callable

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QLabel, QStatusBar

from calib_core.operator.panes.status import StatusLineModel

STALE_CAMERA_S = 2.0
STALE_LINK_S = 1.0
RATE_SPAN_S = 1.0
"""The link's sample rate is counted over at least this much of the controller's clock: over the few milliseconds
between two quick redraws one sample more or less reads as 62 Hz for a 50 Hz stream."""
WARN = "<span style='color:#ff9a30'>{}</span>"


class StatusLine:
    """The status bar's fields, given what they show (a
    :class:`~calib_core.operator.panes.status.StatusLineModel`: the robot's motion and link, the settle rule, the
    pairs, the recording) and the window's ``camera_state()`` ``(last frame received or None, worker or None,
    replaying)``."""

    def __init__(self, bar: QStatusBar, model: StatusLineModel, *, camera_state: Callable[[], tuple], parent) -> None:
        self._model = model
        self._camera_state = camera_state
        self._bar = bar
        self.record_label = QLabel("")
        self.link_label = QLabel("link: not connected")
        self.fps_label = QLabel("camera: -")
        self.pairs_label = QLabel("pairs: 0")
        self.motion_label = QLabel("robot: no move yet")
        self.motion_label.setObjectName("motion")
        self.settled_label = QLabel("")
        self.settled_label.setObjectName("settled")
        for w in (
            self.motion_label,
            self.settled_label,
            self.record_label,
            self.link_label,
            self.fps_label,
            self.pairs_label,
        ):
            bar.addPermanentWidget(w)
        # the fields take most of the bar, and a long message (Find points' reason, an error) is cut at what is left:
        # the whole of it is the bar's tooltip while it shows; each field says what it is, so hovering one does not
        # show the message instead
        # (through a Python callable: PySide cannot connect a signal to QStatusBar.setToolTip itself and says so on
        # stderr at every start)
        bar.messageChanged.connect(self._message_as_tooltip)
        self.record_label.setToolTip("the session's recording: shown while it records, with how much it holds")
        self.link_label.setToolTip(
            "the robot link: its state, joint samples a second, lines rejected, and a far controller's one-way delay"
        )
        self.fps_label.setToolTip("the camera: frames a second, orange when none came for a while")
        self.pairs_label.setToolTip("the point pairs picked, and those the last solve used")
        model.motion_changed.connect(self.show_motion)
        model.link_state.connect(self.show_link_state)
        # (pairs change outside the undo stack too)
        for signal in (model.pairs_changed, model.result_changed, model.target_changed):
            signal.connect(self.show_pairs)
        self.show_pairs()
        self._samples_then: tuple[tuple[str, float], int] | None = None  # ((which clock, its time s), samples then)
        self._rate_text = ""  # the last rate counted over RATE_SPAN_S
        self.timer = QTimer(parent)
        self.timer.setInterval(1000)
        self.timer.timeout.connect(self.update)
        self.timer.start()

    def _message_as_tooltip(self, text: str) -> None:
        self._bar.setToolTip(text)

    def update(self) -> None:
        now = time.monotonic()
        frame, worker, replaying = self._camera_state()
        if replaying:
            self.fps_label.setText("camera: replaying a recording")
        elif worker is not None and not worker.paused:
            age = None if frame is None else now - frame.t_host_s
            if age is not None and age > STALE_CAMERA_S:
                self.fps_label.setText(WARN.format(f"camera: no frame for {age:.0f} s"))
            else:
                self.fps_label.setText(f"camera: {worker.fps_measured:.1f} fps")
        link = self._model.link()
        if link is not None:
            s = link.stats_snapshot()
            # the rate by the controller's own clock (the samples' stamps): a far link delivers in bursts, and
            # counting arrivals per second of ours showed 182 Hz for a 50 Hz stream
            latest = link.latest
            clock = ("ours", now) if latest is None else ("controller's", latest.sample.t_ms / 1000.0)
            prev = self._samples_then
            if prev is None or prev[0][0] != clock[0] or clock[1] < prev[0][1]:
                self._samples_then, self._rate_text = (clock, s["samples"]), ""  # a new clock: counted afresh
            elif clock[1] - prev[0][1] >= RATE_SPAN_S:
                self._rate_text = f"{(s['samples'] - prev[1]) / (clock[1] - prev[0][1]):.0f} Hz, "
                self._samples_then = (clock, s["samples"])
            rate = self._rate_text
            delay = link.delay_s
            delay_text = "" if delay is None else f", delay {delay:.2f} s" if delay >= 0.01 else ", delay < 0.01 s"
            text = (
                f"link: {link.state.value}, {rate}{s['samples']} samples, {s['bad_checksum'] + s['malformed']} "
                f"rejected{delay_text}"
            )
            last = self._model.last_sample_s
            # a far link delivers its samples in bursts: late only past its own spread of delays
            late_after = STALE_LINK_S + link.stale_after_now_s()
            if link.state.value == "up" and last is not None and now - last > late_after:
                text = WARN.format(f"link: up but no joint sample for {now - last:.1f} s")
            self.link_label.setText(text)
        self._show_settled()
        rec = self._model.recorder
        self.record_label.setText(
            "" if rec is None else f"<span style='color:#ff4040'>&#9679; REC</span> {rec.size_bytes / 1e6:.1f} MB"
        )

    def show_motion(self, state) -> None:
        """Moving / arrived / refused / pose unknown, from the controller's answers."""
        color = {
            "moving": "#9ad0ff",
            "arrived": "#5fd35f",
            "refused": "#ff6b6b",
            "failed": "#ff6b6b",
            "unknown": "#ff9a30",
        }.get(state.motion.value)
        self.motion_label.setText(
            f"<span style='color:{color}'>{html.escape(state.text, quote=False)}</span>"
            if color
            else html.escape(state.text)
        )
        self.motion_label.setToolTip(state.text)
        self._show_settled()

    def _show_settled(self) -> None:
        """Whether the newest frame can be picked on: the settle rule, from the joint samples."""
        if self._model.link() is None and not self._model.replaying:
            self.settled_label.setText("")
            return
        still = self._model.robot_settled()
        self.settled_label.setText(
            "<span style='color:#5fd35f'>settled</span>"
            if still.settled
            else "<span style='color:#ff9a30'>not settled</span>"
        )
        self.settled_label.setToolTip(still.reason or f"still for {still.still_for_s:.1f} s: frames can be picked on")

    def show_pairs(self, *_) -> None:
        self.pairs_label.setText(f"pairs: {self._model.usable_pairs}/{self._model.required_pairs} needed")

    def show_link_state(self, text: str) -> None:
        self.link_label.setText(
            f"link: {html.escape(text, quote=False)}"
        )  # the label shows markup (warnings); a device's text is not
