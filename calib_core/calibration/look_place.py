"""Where a look was made, against the task location it would correct.

A robot's kinematic error is a rigid motion about the joint that causes it, so it changes with the
pose: a look from the approach pose, 200 mm back, stored as the task's correction left the tool
1.6 mm off the task. A look counts for a task location only when it was made live at that
location's pose, or at its corrected pose (the refining second look), within the task's tolerance.
Anything else (another pose, a recording) is a measurement at its own pose, and becomes the task's
correction only when the operator converts it explicitly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.calibration.errors import CalibrationError
from calib_core.frames import pose_difference

LEVER_MM = 100.0
"""The rotational tolerance of a look's place is the task's tolerance seen at this lever (mm): a
tool turned by ``tolerance / LEVER_MM`` rad moves a point 100 mm away by the tolerance."""


@dataclass(frozen=True)
class LookPlace:
    """``at``: ``task`` (the task location's pose), ``corrected`` (its corrected pose), ``elsewhere``
    or ``recording``; ``offset_mm`` / ``offset_deg``: the modelled TCP at the look's joints from the
    nearest of those poses (mm, deg); ``tolerance_mm`` / ``tolerance_deg``: what counts as there;
    ``source``: the recording's name for a recorded look."""

    task: str
    at: str
    offset_mm: float
    offset_deg: float
    tolerance_mm: float
    tolerance_deg: float
    source: str = "live"

    @property
    def counts(self) -> bool:
        """Whether the look may become the task's correction without an explicit conversion."""
        return self.at in ("task", "corrected")

    @property
    def text(self) -> str:
        """One sentence for the operator."""
        if self.at == "recording":
            return f"the look was made on the recording {self.source}, not live at {self.task}"
        if self.at == "elsewhere":
            return (
                f"the look was made {self.offset_mm:.1f} mm and {self.offset_deg:.2f} deg from {self.task}'s pose "
                f"(tolerance {self.tolerance_mm:g} mm, {self.tolerance_deg:.2f} deg)"
            )
        where = "pose" if self.at == "task" else "corrected pose"
        return (
            f"the look was made at {self.task}'s {where} ({self.offset_mm:.2f} mm, {self.offset_deg:.3f} deg from it)"
        )


def place_of_look(
    task, tcp2base_at_look: np.ndarray, corrected2base: np.ndarray | None, view_sources: tuple[str, ...]
) -> LookPlace:
    """Where a look was made for ``task`` (a :class:`~calib_core.workcell.model.TaskLocation`):
    ``tcp2base_at_look`` (4, 4) mm, the modelled TCP at the look's joints; ``corrected2base`` (4, 4) mm
    the task's corrected target (``None`` without a stored correction); ``view_sources``: the recordings the
    look's frames came from, by name (empty: every frame live)."""
    tolerance_mm = float(task.tolerance_mm)
    tolerance_deg = float(np.degrees(tolerance_mm / LEVER_MM))
    places = {"task": task.tcp2base}
    if corrected2base is not None:
        places["corrected"] = corrected2base
    offsets = {}
    for name, pose in places.items():
        d, r = pose_difference(tcp2base_at_look, pose)
        offsets[name] = (float(np.linalg.norm(d)), float(np.linalg.norm(r)))
    nearest = min(offsets, key=lambda k: offsets[k][0] / tolerance_mm + offsets[k][1] / tolerance_deg)
    mm, deg = offsets[nearest]
    if view_sources:
        return LookPlace(task.name, "recording", mm, deg, tolerance_mm, tolerance_deg, ", ".join(view_sources))
    if mm > tolerance_mm or deg > tolerance_deg:
        return LookPlace(task.name, "elsewhere", mm, deg, tolerance_mm, tolerance_deg)
    return LookPlace(task.name, nearest, mm, deg, tolerance_mm, tolerance_deg)


class LookNotAtTask(CalibrationError):
    """*Store correction* of a look that does not count for the task location (``place``): it can be
    stored as a measurement at its own pose, or converted into the task's correction explicitly.
    ``change_mm`` / ``change_deg``: how far the converted correction would move the commanded target."""

    def __init__(self, place: LookPlace, change_mm: float, change_deg: float):
        self.place, self.change_mm, self.change_deg = place, change_mm, change_deg
        super().__init__(
            f"{place.text}: it is not {place.task}'s correction. Store it as a measurement at that pose, or convert it "
            "explicitly "
            f"(the target commanded for {place.task} would move by {change_mm:.2f} mm, {change_deg:.3f} deg)"
        )
