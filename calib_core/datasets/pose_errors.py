"""The pose errors the BOP benchmark scores by (Hodan et al., "BOP Challenge 2020 on 6D Object Localization"):
MSSD, the largest distance in space between the model's points at the estimated and the true pose, and MSPD, the
largest distance between their projections, each the least over the object's symmetries; and the plain
translation and rotation errors. Recall at BOP's thresholds (MSSD: 5-50 % of the diameter; MSPD: 5-50 px at a
640 px wide image, scaled with the width) averaged is the benchmark's AR for each.
"""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points

MSSD_THRESHOLDS = np.arange(0.05, 0.51, 0.05)
"""Fractions of the object's diameter."""
MSPD_THRESHOLDS_PX = np.arange(5.0, 51.0, 5.0)
"""Pixels at an image 640 px wide."""


def _posed(points: np.ndarray, obj2cam: np.ndarray) -> np.ndarray:
    return points @ obj2cam[:3, :3].T + obj2cam[:3, 3]


def mssd(estimate: np.ndarray, truth: np.ndarray, points_mm: np.ndarray, symmetries: np.ndarray) -> float:
    """Maximum symmetry-aware surface distance, mm: over the symmetries S (k, 4, 4), the least of the largest
    distance between ``points_mm`` (n, 3, the model's frame) at ``estimate`` and at ``truth`` @ S (both 4 x 4)."""
    at_estimate = _posed(points_mm, estimate)
    return float(min(np.max(np.linalg.norm(at_estimate - _posed(points_mm, truth @ s), axis=1)) for s in symmetries))


def mspd(
    estimate: np.ndarray, truth: np.ndarray, points_mm: np.ndarray, symmetries: np.ndarray, intrinsics: Intrinsics
) -> float:
    """Maximum symmetry-aware projection distance, px: as :func:`mssd` between the points' pixels through
    ``intrinsics``."""
    at_estimate = project_points(points_mm, estimate, intrinsics)
    return float(
        min(
            np.max(np.linalg.norm(at_estimate - project_points(points_mm, truth @ s, intrinsics), axis=1))
            for s in symmetries
        )
    )


def translation_error_mm(estimate: np.ndarray, truth: np.ndarray) -> float:
    """How far apart the two poses put the model's origin, mm."""
    return float(np.linalg.norm(estimate[:3, 3] - truth[:3, 3]))


def rotation_error_deg(estimate: np.ndarray, truth: np.ndarray) -> float:
    """The angle of the turn between the two poses' rotations, degrees."""
    cos = (np.trace(estimate[:3, :3] @ truth[:3, :3].T) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))


def average_recall(errors: np.ndarray, thresholds: np.ndarray) -> float:
    """The share of ``errors`` (a failure as inf) under each threshold, averaged over the thresholds."""
    errors = np.asarray(errors, dtype=float)
    if errors.size == 0:
        return float("nan")
    return float(np.mean([(errors < t).mean() for t in thresholds]))
