"""Which views of a hand-eye set disagree with the rest: each view's residual in the image and how far the board's
place predicted from it lies from the others', each against the set's own typical value.

A real set holds views whose robot pose was recorded wrong (a pose read before the robot settled, a tool frame
changed between poses) or whose board was detected badly (blur, a cut-off board). Both show as a view that stands
out from the others: its corners fit worse than the typical view's, or the board's place in the base predicted from
it (flange2base . cam2flange . board2cam) lies further from the mean than the typical view's does. Typical is the
median (the odd view does not move it); the floors keep a set that agrees to a tenth of a millimetre from calling a
view at three tenths a bad one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DISAGREE_FACTOR = 3.0
"""A view stands out when its residual or its distance is over this many times the set's median."""
FLOOR_PX = 0.5
"""A view's residual under this (px) never stands out: a corner detector's noise on a sharp real image."""
FLOOR_MM = 1.0
"""A view's distance from the others under this (mm) never stands out: an industrial robot's pose accuracy."""


@dataclass(frozen=True)
class ViewCheck:
    """One view of a hand-eye calibration: ``rms_px`` its corners' residual, ``apart_mm`` how far the board's place
    predicted from it lies from the mean of all views'; ``agrees`` False when either stands out (``why`` says
    which)."""

    name: str
    rms_px: float
    apart_mm: float
    agrees: bool
    why: str = ""


def view_checks(names, rms_px, apart_mm) -> tuple[ViewCheck, ...]:
    """Each view's :class:`ViewCheck` from its name, residual (px) and distance (mm), in the calibration's order."""
    rms, apart = np.asarray(rms_px, dtype=float), np.asarray(apart_mm, dtype=float)
    rms_bound = max(DISAGREE_FACTOR * float(np.median(rms)), FLOOR_PX) if len(rms) else np.inf
    mm_bound = max(DISAGREE_FACTOR * float(np.median(apart)), FLOOR_MM) if len(apart) else np.inf
    out = []
    for name, r, a in zip(names, rms, apart):
        why = []
        if r > rms_bound:
            why.append(f"its corners fit to {r:.2f} px where the views' median is {np.median(rms):.2f} px")
        if a > mm_bound:
            why.append(
                f"the board's place predicted from it lies {a:.1f} mm from the others' mean (median "
                f"{np.median(apart):.1f} mm): its robot pose or its board detection is off"
            )
        out.append(ViewCheck(str(name), float(r), float(a), not why, "; ".join(why)))
    return tuple(out)
