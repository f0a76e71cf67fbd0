"""How far and how high a robot reaches, from its kinematics alone."""

from __future__ import annotations

import numpy as np

from calib_core.robot.model import RobotModel


def reach_of(robot: RobotModel, samples: int = 400, seed: int = 0) -> tuple[float, float]:
    """The flange's horizontal reach (mm, the 90th percentile over random joints within the limits)
    and its median height (mm) in the base frame."""
    rng = np.random.default_rng(seed)
    lo = np.maximum(robot.lower_limits_deg, -180.0)
    hi = np.minimum(robot.upper_limits_deg, 180.0)
    points = np.array([robot.fk(rng.uniform(lo, hi), "flange")[:3, 3] for _ in range(samples)])
    return float(np.percentile(np.hypot(points[:, 0], points[:, 1]), 90)), float(np.median(points[:, 2]))
