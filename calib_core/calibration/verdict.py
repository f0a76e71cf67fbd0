"""Whether a calibration result can be used: the solver's status, then plausibility against what
the cell states (its model error, the task's tolerance), and whether it is still the result of the
pairs on screen.

A solve can fit its pixels perfectly and still be wrong for the robot: pairs picked at another
pose, a wrong target, a mounting that is not the one modelled. Such a result moves the end effector
by far more than a robot model can be off; it gets its own status, and storing it needs a
confirmation that is kept with the correction.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

from calib_core.solver.solution import SolveStatus
from calib_core.workcell.safety import DEFAULT_TOLERANCE_MM, SafetyLimits


class Verdict(str, Enum):
    """``ok``: usable as it is; ``ambiguous``: several poses fit (choose one); ``implausible``: the
    displacement is beyond the cell's model error; ``uncertain``: its 1-sigma is over the task's
    tolerance (or unknown); ``failed``: no pose."""

    OK = "ok"
    AMBIGUOUS = "ambiguous"
    IMPLAUSIBLE = "implausible"
    UNCERTAIN = "uncertain"
    FAILED = "failed"


@dataclass(frozen=True)
class ResultVerdict:
    """``verdict`` and its ``reasons`` in words (empty for ``ok``)."""

    verdict: Verdict
    reasons: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.verdict is Verdict.OK

    @property
    def storable(self) -> bool:
        """A correction can be stored from it (with a confirmation unless ``ok``)."""
        return self.verdict is not Verdict.FAILED

    @property
    def text(self) -> str:
        return self.verdict.value.upper() + (": " + "; ".join(self.reasons) if self.reasons else "")


def judge(estimate, limits: SafetyLimits | None = None, tolerance_mm: float = DEFAULT_TOLERANCE_MM) -> ResultVerdict:
    """The verdict on an :class:`~calib_core.calibration.end_effector.EndEffectorEstimate`."""
    limits = limits or SafetyLimits()
    solution = estimate.solution
    if solution.status is SolveStatus.FAILED:
        return ResultVerdict(Verdict.FAILED, (solution.reason or "no pose fits the pairs",))
    d_mm = float(np.linalg.norm(estimate.displacement_mm))
    r_deg = float(np.linalg.norm(estimate.rotation_deg))
    implausible = []
    if d_mm > limits.model_error_mm:
        implausible.append(
            f"the end effector would be {d_mm:.1f} mm from the model, beyond the cell's stated model error of "
            f"{limits.model_error_mm:g} mm"
        )
    if r_deg > limits.model_error_deg:
        implausible.append(
            f"it would be turned {r_deg:.2f} deg from the model, beyond the cell's stated {limits.model_error_deg:g} "
            "deg"
        )
    if implausible:
        implausible.append("check that the pairs belong to this robot pose and object, and the camera mounting")
        return ResultVerdict(Verdict.IMPLAUSIBLE, tuple(implausible))
    if solution.status is SolveStatus.AMBIGUOUS:
        return ResultVerdict(
            Verdict.AMBIGUOUS,
            (f"{len(solution.candidates)} poses fit the pairs equally well: choose one, or add pairs",),
        )
    sigma = np.asarray(estimate.std_displacement_mm, float)
    if not np.all(np.isfinite(sigma)):
        return ResultVerdict(Verdict.UNCERTAIN, ("the result has no uncertainty (too few pairs for one): add pairs",))
    sigma_mm = float(np.linalg.norm(sigma))
    if sigma_mm > tolerance_mm:
        return ResultVerdict(
            Verdict.UNCERTAIN,
            (
                f"its 1-sigma of {sigma_mm:.2f} mm is over the task's tolerance of {tolerance_mm:g} mm: add pairs "
                "spread over the object",
            ),
        )
    return ResultVerdict(Verdict.OK)
