"""A robot calibration run: the robot driven through planned poses, one board view captured at each,
then the poses that view the surveyed components, one settled frame kept at each.

Each move is awaited (the arm's ``motion_changed`` says it arrived, or why not), then a frame taken
after the robot settled (the same stillness rule every pick and capture follows) is detected and kept
with the joints at its capture. A refused or failed move, or a stop, ends the run with the reason;
what was captured stays. The operator previewed the whole plan before starting, so each move goes
with ``confirmed``; a move the preview blocks (a collision, a limit) still stops the run.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from psygnal import Signal

from calib_core.errors import VideocalError
from calib_core.operator.arm import Arm
from calib_core.operator.motion import Motion
from calib_core.operator.operator_log import OperatorLog
from calib_core.robot_calibration.identify_robot import CellFrame
from calib_core.vision.capture import BoardCapture
from calib_core.vision.intrinsics_calibration import RejectedView

IDLE, MOVING, SETTLING, DONE, STOPPED = "idle", "moving", "settling", "done", "stopped"
VIA = "via"
"""In a plan's ``cell_views``: a pose passed through on the way to the next (home, round an obstacle), nothing
captured."""
MAX_FRAMES_PER_POSE = 60
"""Settled frames tried at a pose before it is given up (the board not found in any)."""


@dataclass(frozen=True)
class RunProgress:
    """``index`` of the pose being visited (0-based) of ``total``; ``phase``; ``text`` in words."""

    index: int
    total: int
    phase: str
    text: str


class CalibrationRun:
    """Events: ``progress(RunProgress)`` at every step, ``finished(text)`` once."""

    progress = Signal(object)
    finished = Signal(str)

    def __init__(self, arm: Arm, log: OperatorLog, spec, plan: list[np.ndarray], cell_views=()):
        self._arm, self._log = arm, log
        self.capture = BoardCapture(spec)
        self.components = [None] * len(plan) + [c for c, _ in cell_views]
        self.plan = [np.asarray(q, dtype=float) for q in plan] + [np.asarray(q, dtype=float) for _, q in cell_views]
        self.cell_frames: list[CellFrame] = []
        self.index = 0
        self.phase = IDLE
        self.skipped: list[str] = []
        self._tries = 0

    @property
    def what(self) -> str:
        component = self.components[self.index] if self.index < len(self.plan) else None
        return f"calibration pose {self.index + 1} of {len(self.plan)}" + (
            " (on the way, through home)" if component == VIA else f" ({component})" if component else ""
        )

    def start(self) -> None:
        if not self.plan:
            raise VideocalError("no poses planned: plan the robot calibration first")
        self._arm.motion_changed.connect(self._on_motion)
        self._arm.observations.frame_observed.connect(self._on_frame)
        self._visit()

    def stop(self, why: str = "stopped by the operator") -> None:
        if self.phase in (DONE, STOPPED):
            return
        self._end(
            STOPPED,
            f"calibration run stopped at pose {self.index + 1} of {len(self.plan)}: {why}; {len(self.capture.views)} "
            "views kept",
        )

    def _end(self, phase: str, text: str) -> None:
        self.phase = phase
        self._arm.motion_changed.disconnect(self._on_motion)
        self._arm.observations.frame_observed.disconnect(self._on_frame)
        self._say(text)
        self.finished.emit(text)

    def _say(self, text: str) -> None:
        self.progress.emit(RunProgress(self.index, len(self.plan), self.phase, text))
        self._log.say(text)

    def _visit(self) -> None:
        if self.index >= len(self.plan):
            self._end(
                DONE,
                f"calibration run done: {len(self.capture.views)} board views and {len(self.cell_frames)} of the "
                f"surveyed components from {len(self.plan)} poses"
                + (f" ({len(self.skipped)} skipped)" if self.skipped else ""),
            )
            return
        self.phase, self._tries = MOVING, 0
        try:
            self._arm.move_joints(self.plan[self.index], self.what, confirmed=True)
        except VideocalError as exc:
            self.stop(str(exc))
            return
        self._say(f"{self.what}: moving")

    def _on_motion(self, state) -> None:
        if self.phase != MOVING or state.what != self.what:
            return
        if state.motion is Motion.ARRIVED and self.components[self.index] == VIA:
            self.index += 1
            self._visit()
        elif state.motion is Motion.ARRIVED:
            self.phase = SETTLING
            self._say(f"{self.what}: arrived, waiting for the robot to settle")
        elif state.motion is not Motion.MOVING:
            self.stop(state.text)

    def _on_frame(self, frame) -> None:
        if self.phase != SETTLING or not self._arm.observations.stillness(frame).settled:
            return
        try:
            joints = np.array(self._arm.observations.stamp(frame).joints_deg)
        except VideocalError:  # settled, but its joints not known yet (a sample late): the next frame
            return
        if self.components[self.index] is not None:
            self.cell_frames.append(CellFrame(self.components[self.index], joints, frame.image.copy()))
            self.index += 1
            self._visit()
            return
        view = self.capture.add(frame.image, joints)
        if isinstance(view, RejectedView):
            self._tries += 1
            if self._tries < MAX_FRAMES_PER_POSE:
                return
            self.skipped.append(f"pose {self.index + 1}: {view.reason}")
        self.index += 1
        self._visit()
