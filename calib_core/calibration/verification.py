"""A second look after executing a task with its correction: how far the real tool still is from
the task location, with its 1-sigma, and whether the two looks agree.

The correction was measured at the task location (look 1: the real tool ``Δ1`` from the model
there). Executed, the robot stands at the corrected joints; a look from there (look 2) measures the
real tool again. The remaining error is that tool's pose against the task location; the looks agree
when the correction predicted where the tool went: the real tool at the corrected joints, as look 1's
``Δ1`` puts it, against look 2, within three times their combined 1-sigma *and* within the task's
tolerance. Uncertain looks do not buy agreement: two looks 1.6 mm apart with a 0.56 mm 1-sigma
each were once called "agree" for a task that needs 1 mm.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from calib_core.frames import concat, pose_difference
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM


@dataclass(frozen=True)
class Verification:
    """``remaining_mm`` (3,) and ``remaining_deg`` (3,): the real tool (look 2) minus the task
    location, base frame, with ``std_remaining_mm`` (3,) its 1-sigma; ``disagreement_mm``: look 2's
    tool against where look 1 predicted it; ``agree_within_mm``: three times the combined 1-sigma,
    at most the task's ``tolerance_mm``; ``agree``; ``within_tolerance``: the tool within the
    task's tolerance."""

    task: str
    remaining_mm: np.ndarray
    remaining_deg: np.ndarray
    std_remaining_mm: np.ndarray
    disagreement_mm: float
    agree_within_mm: float
    rms_px: float
    pairs: int
    time_s: float = field(default_factory=time.time)
    tolerance_mm: float = DEFAULT_TOLERANCE_MM

    @property
    def agree(self) -> bool:
        limit = min(self.agree_within_mm, self.tolerance_mm)
        return bool(np.isfinite(limit) and self.disagreement_mm <= limit)

    @property
    def within_tolerance(self) -> bool:
        return bool(np.linalg.norm(self.remaining_mm) <= self.tolerance_mm)

    @property
    def ok(self) -> bool:
        """The looks agree and the tool is within the task's tolerance."""
        return self.agree and self.within_tolerance

    @property
    def judgement(self) -> str:
        """A few words for the corrections' summary."""
        looks = "looks agree" if self.agree else "looks DISAGREE"
        return looks + ("" if self.within_tolerance else f", OUTSIDE the {self.tolerance_mm:g} mm tolerance")

    @property
    def text(self) -> str:
        d, s = self.remaining_mm, self.std_remaining_mm
        limit = min(self.agree_within_mm, self.tolerance_mm)
        return (
            f"{self.task}: the tool is {np.linalg.norm(d):.2f} mm (1-sigma {np.linalg.norm(s):.2f} mm) and "
            f"{np.linalg.norm(self.remaining_deg):.3f} deg "
            f"from the task location, {'within' if self.within_tolerance else 'OUTSIDE'} its {self.tolerance_mm:g} mm "
            "tolerance; "
            f"the two looks {'agree' if self.agree else 'DISAGREE'} ({self.disagreement_mm:.2f} mm apart, "
            f"{'within' if self.agree else 'over'} {limit:.2f} mm: 3 x their 1-sigma {self.agree_within_mm:.2f} mm, "
            f"the tolerance {self.tolerance_mm:g} mm)"
        )


def verify(
    task: str, target2base: np.ndarray, correction, look, tolerance_mm: float = DEFAULT_TOLERANCE_MM
) -> Verification:
    """``correction``: the stored :class:`~calib_core.calibration.corrections.Correction` (look 1);
    ``look``: the :class:`~calib_core.calibration.end_effector.EndEffectorEstimate` from the corrected
    joints (look 2); ``target2base`` (4, 4) mm the task location; ``tolerance_mm`` the task's."""
    remaining, rotation = pose_difference(look.tcp2base_measured, target2base)
    predicted = concat(look.tcp2base_model, correction.delta_base)  # look 1's Δ at the pose look 2 was made from
    disagreement = float(np.linalg.norm(look.tcp2base_measured[:3, 3] - predicted[:3, 3]))
    sigma = float(
        np.sqrt(np.sum(np.square(correction.std_displacement_mm)) + np.sum(np.square(look.std_displacement_mm)))
    )
    return Verification(
        task,
        remaining,
        rotation,
        np.asarray(look.std_displacement_mm, float),
        disagreement,
        3.0 * sigma,
        float(look.solution.rms_px),
        len(look.solution.residuals_px),
        tolerance_mm=float(tolerance_mm),
    )
