"""Joint-space motion of the simulated controller: synchronised trapezoidal moves.

All joints start and stop together; the slowest joint (distance over its speed limit) sets
the duration. Positions in degrees, times in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

# Fraction of a move spent accelerating (and the same decelerating).
_RAMP_FRACTION = 0.2


class JointModel(Protocol):
    """What the simulator needs of a robot: limits and speeds per joint (``RobotModel`` has them)."""

    @property
    def lower_limits_deg(self) -> np.ndarray: ...

    @property
    def upper_limits_deg(self) -> np.ndarray: ...

    @property
    def max_speed_deg_s(self) -> np.ndarray: ...


@dataclass(frozen=True)
class PlainJointModel:
    """A joint-space robot with the given limits (deg) and speeds (deg/s)."""

    lower_limits_deg: np.ndarray = field(default_factory=lambda: np.full(6, -170.0))
    upper_limits_deg: np.ndarray = field(default_factory=lambda: np.full(6, 170.0))
    max_speed_deg_s: np.ndarray = field(default_factory=lambda: np.array([100.0, 100.0, 100.0, 200.0, 200.0, 300.0]))


@dataclass(frozen=True)
class TrapezoidMove:
    """A move from ``start_deg`` to ``goal_deg`` (6,) beginning at ``t0_s`` and lasting ``duration_s``."""

    start_deg: np.ndarray
    goal_deg: np.ndarray
    t0_s: float
    duration_s: float

    @classmethod
    def plan(
        cls,
        start_deg: np.ndarray,
        goal_deg: np.ndarray,
        max_speed_deg_s: np.ndarray,
        t0_s: float,
        speed_scale: float = 1.0,
    ) -> TrapezoidMove:
        distance = np.abs(np.asarray(goal_deg, float) - np.asarray(start_deg, float))
        # Peak speed = distance / (duration * (1 - ramp)): choose the duration that keeps every joint within its limit.
        per_joint = distance / (np.asarray(max_speed_deg_s, float) * speed_scale * (1.0 - _RAMP_FRACTION))
        return cls(np.asarray(start_deg, float), np.asarray(goal_deg, float), t0_s, float(max(per_joint.max(), 1e-3)))

    def fraction(self, t_s: float) -> float:
        """Progress in [0, 1] along the trapezoidal velocity profile."""
        T = self.duration_s
        r = _RAMP_FRACTION * T
        t = min(max(t_s - self.t0_s, 0.0), T)
        v_peak = 1.0 / (T - r)
        if t < r:
            return 0.5 * v_peak * t * t / r
        if t <= T - r:
            return 0.5 * v_peak * r + v_peak * (t - r)
        remaining = T - t
        return 1.0 - 0.5 * v_peak * remaining * remaining / r

    def position(self, t_s: float) -> np.ndarray:
        return self.start_deg + self.fraction(t_s) * (self.goal_deg - self.start_deg)

    def finished(self, t_s: float) -> bool:
        return t_s >= self.t0_s + self.duration_s
