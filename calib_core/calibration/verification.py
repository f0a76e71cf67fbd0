"""A second look after executing a task with its correction: how far the real tool still is from
the task location, with its 1-sigma, and whether the two looks agree.

The correction was measured at the task location (look 1: the real tool ``Δ1`` from the model
there). Executed, the robot stands at the corrected joints; a look from there (look 2) measures the
real tool again. The remaining error is that tool's pose against the task location; the looks agree
when the correction predicted where the tool went: the real tool at the corrected joints, as look 1's
``Δ1`` puts it, against look 2, within three times their combined 1-sigma.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from calib_core.frames import pose_difference


@dataclass(frozen=True)
class Verification:
    """``remaining_mm`` (3,) and ``remaining_deg`` (3,): the real tool (look 2) minus the task
    location, base frame, with ``std_remaining_mm`` (3,) its 1-sigma; ``disagreement_mm``: look 2's
    tool against where look 1 predicted it; ``agree_within_mm`` three times the combined 1-sigma;
    ``agree``."""

    task: str
    remaining_mm: np.ndarray
    remaining_deg: np.ndarray
    std_remaining_mm: np.ndarray
    disagreement_mm: float
    agree_within_mm: float
    rms_px: float
    pairs: int
    time_s: float = field(default_factory=time.time)

    @property
    def agree(self) -> bool:
        return bool(np.isfinite(self.agree_within_mm) and self.disagreement_mm <= self.agree_within_mm)

    @property
    def text(self) -> str:
        d, s = self.remaining_mm, self.std_remaining_mm
        return (f"{self.task}: the tool is {np.linalg.norm(d):.2f} mm (1-sigma {np.linalg.norm(s):.2f} mm) and {np.linalg.norm(self.remaining_deg):.3f} deg "
                f"from the task location; the two looks {'agree' if self.agree else 'DISAGREE'} ({self.disagreement_mm:.2f} mm apart, "
                f"{'within' if self.agree else 'over'} {self.agree_within_mm:.2f} mm)")


def verify(task: str, target2base: np.ndarray, correction, look) -> Verification:
    """``correction``: the stored :class:`~calib_core.calibration.corrections.Correction` (look 1);
    ``look``: the :class:`~calib_core.calibration.end_effector.EndEffectorEstimate` from the corrected
    joints (look 2); ``target2base`` (4, 4) mm the task location."""
    remaining, rotation = pose_difference(look.tcp2base_measured, target2base)
    predicted = correction.delta_base @ look.tcp2base_model  # look 1's Δ at the pose look 2 was made from
    disagreement = float(np.linalg.norm(look.tcp2base_measured[:3, 3] - predicted[:3, 3]))
    sigma = float(np.sqrt(np.sum(np.square(correction.std_displacement_mm)) + np.sum(np.square(look.std_displacement_mm))))
    return Verification(task, remaining, rotation, np.asarray(look.std_displacement_mm, float), disagreement, 3.0 * sigma, float(look.solution.rms_px), len(look.solution.residuals_px))
