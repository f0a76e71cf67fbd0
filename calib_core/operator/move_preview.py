"""A move checked before it is sent: the joint path the controller will follow (a joint-space
straight line, as ``MVJ`` interpolates), its limits, its closeness to singularities, collisions
of the robot with itself and the cell along it, and how far each joint turns.

A move that leaves the limits or collides is refused; one that turns a joint further than the
cell's ``confirm_joint_change_deg`` needs the operator's confirmation; closeness to a singularity
is said in words (the wrist spins there for a small tool motion).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from calib_core.errors import OperatorError
from calib_core.robot.collision import CollisionWorld, Contact
from calib_core.robot.model import RobotModel
from calib_core.workcell.safety import SafetyLimits

STEP_DEG = 2.0
"""The path is checked every this many degrees (or mm) of the joint that moves most."""
REACH_SCALE_MM = 1000.0
"""Translation rows of the Jacobian are divided by this (mm) to compare them with rotations."""


@dataclass(frozen=True)
class MovePreview:
    """``what`` (in words), ``start_deg``/``goal_deg`` (n,) and ``path_deg`` (k, n) deg/mm;
    ``joint_change_deg`` (n,) goal minus start; ``limit_margin_deg`` (n,) the smallest distance to
    each joint's limits along the path; ``min_singular``: the smallest singular value of the scaled
    Jacobian along the path, at ``singular_step``; ``contacts``: the first path step in contact and
    its contacts (``None``, ``[]`` when free); ``problems`` refuse the move, ``warnings`` are said,
    ``confirm_reasons`` need a confirmation."""

    what: str
    start_deg: np.ndarray
    goal_deg: np.ndarray
    path_deg: np.ndarray
    joint_change_deg: np.ndarray
    limit_margin_deg: np.ndarray
    min_singular: float
    singular_step: int
    contact_step: int | None
    contacts: list[Contact] = field(default_factory=list)
    problems: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()
    confirm_reasons: tuple[str, ...] = ()
    tcp_path_mm: np.ndarray | None = None
    joint_names: tuple[str, ...] = ()

    @property
    def blocked(self) -> bool:
        return bool(self.problems)

    @property
    def needs_confirmation(self) -> bool:
        return bool(self.confirm_reasons)

    @property
    def summary(self) -> str:
        """One line: the joint change, then what refuses, needs a confirmation or is worth knowing."""
        j = int(np.argmax(np.abs(self.joint_change_deg))) if len(self.joint_change_deg) else 0
        name = self.joint_names[j] if j < len(self.joint_names) else f"joint {j + 1}"
        head = (
            f"{self.what}: joints turn up to {abs(self.joint_change_deg[j]):.1f} ({name})"
            if len(self.joint_change_deg)
            else self.what
        )
        parts = [head, *self.problems, *self.confirm_reasons, *self.warnings]
        if not self.problems and not self.contacts:
            parts.append("no collision along the path")
        return "; ".join(parts)


class MoveRefused(OperatorError):
    """A move the tool does not send: outside the limits, or into a collision (``preview`` says)."""

    def __init__(self, preview: MovePreview):
        super().__init__(f"not moving to {preview.what}: {'; '.join(preview.problems)}")
        self.preview = preview


@dataclass(frozen=True)
class Confirmation:
    """The operator's answer to one prompt: the move to ``what``, asked for when the core had sent
    ``stops_seen`` stops. A Stop after the prompt voids it: the answer then moves nothing."""

    what: str
    stops_seen: int


class MoveNeedsConfirmation(OperatorError):
    """A move sent only once the operator confirms it (``preview.confirm_reasons``); pass
    ``confirmation`` back as ``confirmed=`` to send it."""

    def __init__(self, preview: MovePreview, confirmation: Confirmation | None = None):
        super().__init__(f"the move to {preview.what} needs your confirmation: {'; '.join(preview.confirm_reasons)}")
        self.preview = preview
        self.confirmation = confirmation or Confirmation(preview.what, 0)


def joint_path(start_deg, goal_deg, step_deg: float = STEP_DEG) -> np.ndarray:
    """The straight joint-space path (k, n) from start to goal, every ``step_deg`` at most."""
    start, goal = np.asarray(start_deg, float), np.asarray(goal_deg, float)
    n = max(1, int(np.ceil(np.max(np.abs(goal - start), initial=0.0) / step_deg)))
    return start + (goal - start) * (np.arange(n + 1) / n)[:, None]


def scaled_min_singular(robot: RobotModel, q_deg) -> float:
    """The smallest singular value of the TCP Jacobian with translations in units of
    ``REACH_SCALE_MM``: near 0 at a singularity (a 6-axis arm's wrist with joint 5 near 0)."""
    J = robot.jacobian(q_deg, "tcp")
    scaled = np.vstack([J[:3] / REACH_SCALE_MM, J[3:]])
    return float(np.linalg.svd(scaled, compute_uv=False)[-1])


def preview_move(
    robot: RobotModel,
    world: CollisionWorld | None,
    start_deg,
    goal_deg,
    what: str,
    limits: SafetyLimits | None = None,
    allowed_contacts: frozenset[str] = frozenset(),
) -> MovePreview:
    """Check the move from ``start_deg`` to ``goal_deg`` (deg/mm). ``allowed_contacts``: cell
    components the move may touch (the task's object when going to the task pose itself): said,
    not refused."""
    limits = limits or SafetyLimits()
    start, goal = robot.check_joints(start_deg), robot.check_joints(goal_deg)
    path = joint_path(start, goal)
    lower, upper = robot.lower_limits_deg, robot.upper_limits_deg
    margin = np.min(np.minimum(path - lower, upper - path), axis=0)
    problems, warnings, confirm = [], [], []
    for j in np.flatnonzero(margin < 0):
        problems.append(
            f"joint {robot.joint_names[j]} would go {-margin[j]:.2f} {robot.joint_units[j]} beyond its limits "
            f"[{lower[j]:g}, {upper[j]:g}]"
        )
    singular = np.array([scaled_min_singular(robot, q) for q in path])
    near = np.flatnonzero(singular < limits.singularity_margin)
    k_sing = int(near[0]) if len(near) else int(np.argmin(singular))  # where it first comes near
    if len(near):
        where = (
            "at the goal"
            if k_sing == len(path) - 1
            else ("from the start" if k_sing == 0 else f"{100 * k_sing / (len(path) - 1):.0f} % along the path")
        )
        warnings.append(
            f"near a singularity {where} (smallest singular value {singular.min():.3f} < "
            f"{limits.singularity_margin:g}): small tool motions turn the wrist a lot"
        )
    contact_step, contacts = None, []
    if world is not None:
        # Contacts the robot is in already (the tool at its task, on its object) are how it leaves them,
        # not collisions of the move: said, not refused. A new contact along the path is.
        at_start = set(world.check(path[0]))
        if at_start:
            warnings.append(
                "leaves its contact with "
                + ", ".join(sorted({c.b[5:] if c.b.startswith("cell/") else c.b for c in at_start}))
            )
        for k, q in enumerate(path[1:], start=1):
            hits = [c for c in world.check(q) if c not in at_start]
            if hits:
                contact_step, contacts = k, hits
                break
        touching = [c for c in contacts if c.b.startswith("cell/") and c.b[5:] in allowed_contacts]
        blocking = [c for c in contacts if c not in touching]
        if blocking:
            where = (
                "at the start"
                if contact_step == 0
                else f"{100 * contact_step / max(len(path) - 1, 1):.0f} % along the path"
            )
            problems.append(
                f"collision {where}: "
                + ", ".join(c.text for c in blocking[:4])
                + (f" and {len(blocking) - 4} more" if len(blocking) > 4 else "")
            )
        elif touching:
            warnings.append("touches " + ", ".join(sorted({c.b[5:] for c in touching})) + ", the task's object")
    change = goal - start
    big = np.flatnonzero(np.abs(change) > limits.confirm_joint_change_deg)
    if len(big):
        confirm.append(
            "large joint change: "
            + ", ".join(f"{robot.joint_names[j]} {change[j]:+.1f} {robot.joint_units[j]}" for j in big)
            + f" (over {limits.confirm_joint_change_deg:g})"
        )
    tcp = np.array([robot.fk(q, "tcp")[:3, 3] for q in path])
    return MovePreview(
        what,
        start,
        goal,
        path,
        change,
        margin,
        float(singular.min()),
        k_sing,
        contact_step,
        contacts,
        tuple(problems),
        tuple(warnings),
        tuple(confirm),
        tcp,
        tuple(robot.joint_names),
    )
