"""Between ROS 2's SI joint values (rad, m) and videocal's (deg, mm)."""

from __future__ import annotations

import math

import numpy as np


def user_per_si(units) -> np.ndarray:
    """(n,) degrees per radian or millimetres per metre of each joint (``units``: ``deg``/``mm`` each)."""
    return np.array([180.0 / math.pi if u == "deg" else 1000.0 for u in units])
