"""Moves the operator asks for by name: to a task location (its approach or the task itself, planned
or corrected), and the collision world every move is checked against (the cell as it stands now,
with what is put up in it). The moves themselves, their preview, confirmation and Stop are the arm's
(:mod:`calib_core.operator.arm`); the core's methods here hand them on.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.moves``), given the cell, the session (its
corrections), the task choice and the arm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.connectors.link_types import MoveHandle
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.move_preview import Confirmation, MovePreview
from calib_core.operator.task_choice import TaskChoice
from calib_core.robot import solve_ik

NEAR_LIMIT_DEG = 10.0  # a simulated path's goal this close to a joint limit is worth a warning


@dataclass(frozen=True)
class SimulatedPath:
    """A path the model alone follows (the robot does not move): ``joints_deg`` (n, dof) model joints
    from the current ones to the goal, and ``text``, what the operator should know of it."""

    joints_deg: np.ndarray
    text: str


class Moves:
    """Moves of the core's robot, by name (``core.arm`` makes them)."""

    def __init__(self, cell: Cell, session: CalibrationSession, tasks: TaskChoice, arm: Arm):
        self.cell, self.session, self.tasks, self.arm = cell, session, tasks, arm

    @property
    def task(self):
        return self.tasks.task

    def preview_move(self, q, what: str, allowed_contacts: frozenset[str] = frozenset()) -> MovePreview:
        return self.arm.preview(q, what, allowed_contacts)

    def move_to(self, target2base: np.ndarray, what: str, **options) -> MoveHandle:
        return self.arm.move_to(target2base, what, **options)

    def move_joints(self, q, what: str, **options) -> MoveHandle:
        return self.arm.move_joints(q, what, **options)

    def stop_robot(self) -> bool:
        return self.arm.stop()

    def go_to_task(
        self,
        *,
        approach: bool = True,
        corrected: bool = False,
        wait: bool = False,
        confirmed: bool | Confirmation = False,
    ) -> MoveHandle:
        """Move to the task location's approach (or the task pose itself), as planned or ``corrected``
        by its stored correction."""
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

    def simulate_approach(self, steps: int = 30) -> SimulatedPath:
        """The model's path from the current joints to the task location's approach, straight in joint
        space over ``steps`` steps (IK from the current joints), with the goal's joints near a limit named."""
        if self.task is None:
            raise CalibrationError("choose a task location first")
        robot = self.cell.robot
        start = np.array(self.arm.joints_deg, dtype=float)
        goal = solve_ik(robot, self.task.approach2base, start).q_deg
        margin = np.minimum(goal - robot.lower_limits_deg, robot.upper_limits_deg - goal)
        near = [
            f"joint {robot.joint_names[i]} within {m:.1f} {robot.joint_units[i]} of its limit"
            for i, m in enumerate(margin)
            if m < NEAR_LIMIT_DEG
        ]
        text = "; ".join(near) if near else f"path to {self.task.name}: joints within limits"
        return SimulatedPath(start + (goal - start) * (np.arange(steps + 1)[:, None] / steps), text)
