"""The priors a look on a real photograph starts from: the truth moved and turned by a robot model's error (seeded),
as the real-photo bench, its peers and the suite's regression test draw them."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def moved_prior(truth: np.ndarray, mm: float, deg: float, rng: np.random.Generator) -> np.ndarray:
    """``truth`` (4, 4) moved ``mm`` in a random direction and turned ``deg`` about a random axis (camera frame)."""
    d, axis = rng.normal(size=3), rng.normal(size=3)
    prior = truth.copy()
    prior[:3, :3] = Rotation.from_rotvec(np.radians(deg) * axis / np.linalg.norm(axis)).as_matrix() @ truth[:3, :3]
    prior[:3, 3] = truth[:3, 3] + mm * d / np.linalg.norm(d)
    return prior
