"""Whether a vision result can be used as it is: the checks an intrinsics or a hand-eye result must
pass before it replaces the cell's camera model without a confirmation, and which board views lost
corners against their neighbours.
"""

from __future__ import annotations

import numpy as np

from calib_core.workcell.safety import SafetyLimits

MAX_INTRINSICS_RMS_PX = 1.0
"""Board corners refine to a few tenths of a pixel: an intrinsics fit above this has bad views."""
MAX_FOCAL_CHANGE = 0.10
"""A calibrated focal length this far (relative) from the cell's file is another lens, or a bad fit."""
LOST_CORNERS = 0.75
"""A view with fewer corners than this share of its neighbours' typical count is flagged."""


def intrinsics_problems(result, nominal=None) -> list[str]:
    """Reasons an :class:`~calib_core.vision.intrinsics_calibration.IntrinsicsCalibration` should not
    be applied without a confirmation (empty: none)."""
    problems = []
    if result.rms_px > MAX_INTRINSICS_RMS_PX:
        problems.append(
            f"the fit's RMS of {result.rms_px:.2f} px is over {MAX_INTRINSICS_RMS_PX:g} px (board corners refine to a "
            "few tenths): remove blurred or mis-detected views"
        )
    if nominal is not None:
        change = max(abs(result.intrinsics.fu / nominal.fu - 1.0), abs(result.intrinsics.fv / nominal.fv - 1.0))
        if change > MAX_FOCAL_CHANGE:
            problems.append(
                f"the focal lengths differ from the cell's camera file by {100 * change:.0f} % (another lens, or a bad "
                "fit)"
            )
    return problems


def hand_eye_problems(
    result, model_difference: tuple[float, float], noise_px: float | None = None, limits: SafetyLimits | None = None
) -> list[str]:
    """Reasons a :class:`~calib_core.vision.hand_eye.HandEyeCalibration` should not be applied without
    a confirmation. ``model_difference``: (mm, deg) from the modelled mounting; ``noise_px``: the
    corner noise measured by an intrinsics fit of the views (``None``: the result's own measure, each
    view's board pose fitted alone)."""
    limits = limits or SafetyLimits()
    problems = list(result.warnings)
    measured = noise_px is not None
    noise = (
        max(float(noise_px if measured else result.noise_px), 0.1)
        if (measured or np.isfinite(result.noise_px))
        else 0.5
    )
    disagree = any("do not agree" in w for w in result.warnings)
    if not disagree and result.rms_px > 3.0 * noise:
        problems.append(
            f"the views do not agree on one mounting: RMS {result.rms_px:.2f} px, over 3 x the corner noise of "
            f"{noise:.2f} px"
            f"{' measured by the intrinsics fit' if measured else ' (each view fitted alone)'}"
        )
    d_mm, d_deg = model_difference
    if d_mm > limits.model_error_mm or d_deg > limits.model_error_deg:
        problems.append(
            f"it differs from the modelled mounting by {d_mm:.1f} mm and {d_deg:.2f} deg, beyond the cell's stated "
            f"model error ({limits.model_error_mm:g} mm, {limits.model_error_deg:g} deg)"
        )
    return problems


def views_with_lost_corners(counts: list[int], window: int = 2) -> dict[int, float]:
    """Views (index -> their neighbours' median count) with fewer than ``LOST_CORNERS`` of the corners
    the ``window`` views on each side have: a board partly out of view, blur, a glare."""
    flagged = {}
    for i, n in enumerate(counts):
        neighbours = [counts[j] for j in range(max(0, i - window), min(len(counts), i + window + 1)) if j != i]
        if neighbours:
            typical = float(np.median(neighbours))
            if n < LOST_CORNERS * typical:
                flagged[i] = typical
    return flagged
