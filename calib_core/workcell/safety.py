"""What the cell's owner states about its robot and its tasks, and what the tool checks against
it: how wrong the robot model can plausibly be, when the robot counts as still, which moves need
a confirmation.

The workcell file's optional ``safety`` section sets them; every key has a default.
"""

from __future__ import annotations

from dataclasses import dataclass

from calib_core.link.joint_history import SettleRule

SAFETY_KEYS = {
    "model_error_mm",
    "model_error_deg",
    "settle_speed_deg_s",
    "settle_time_s",
    "confirm_joint_change_deg",
    "singularity_margin",
}


@dataclass(frozen=True)
class SafetyLimits:
    """``model_error_mm`` / ``model_error_deg``: the largest displacement of the real end effector
    from the model the cell can have (a measured one beyond it is implausible: stale picks, the
    wrong object, a wrong mounting); ``settle_speed_deg_s`` and ``settle_time_s``: the robot is still
    when every joint is slower than this for that long (deg/s, mm/s for a prismatic joint);
    ``confirm_joint_change_deg``: a move that turns any joint further needs a confirmation;
    ``singularity_margin``: a pose whose smallest singular value of the (scaled) Jacobian is below
    this is reported as near a singularity."""

    model_error_mm: float = 25.0
    model_error_deg: float = 3.0
    settle_speed_deg_s: float = 0.5
    settle_time_s: float = 0.3
    confirm_joint_change_deg: float = 30.0
    singularity_margin: float = 0.05

    @property
    def settle_rule(self) -> SettleRule:
        return SettleRule(speed_deg_s=self.settle_speed_deg_s, hold_s=self.settle_time_s)


DEFAULT_TOLERANCE_MM = 1.0
"""A task location's positioning tolerance when its file states none (mm)."""
