"""Errors about the robot model that a user can cause."""

from __future__ import annotations

from calib_core.errors import VideocalError


class RobotModelError(VideocalError, ValueError):
    """A robot model or a joint vector that cannot be used."""


class UnknownFrameError(RobotModelError):
    """A frame name the robot model does not have. ``known`` lists the ones it has."""

    def __init__(self, name: str, known: list[str]):
        self.name = name
        self.known = known
        super().__init__(f"the robot has no frame '{name}'; known frames: {', '.join(known)}")


class UnreachableTargetError(RobotModelError):
    """No joint vector within the limits puts the frame at the target. ``best`` is the closest
    attempt: (position error mm, rotation error deg)."""

    def __init__(self, message: str, best: tuple[float, float]):
        self.best = best
        super().__init__(message)


class RobotSpecError(RobotModelError):
    """A workcell's robot section that does not fit its URDF (a frame, joint or base it names).
    ``field`` is the workcell field (``robot.frames.flange``), ``detail`` the reason."""

    def __init__(self, field: str, detail: str, urdf=None):
        self.field = field
        self.detail = detail
        super().__init__(f"{urdf}: {field}: {detail}" if urdf else f"{field}: {detail}")
