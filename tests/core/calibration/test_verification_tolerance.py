"""*Verify* judges two looks against the task's tolerance as well as their 1-sigma (1.61 mm
apart with a 1.68 mm 3-sigma was called "agree" for a task that needs 1 mm)."""

import numpy as np
import pytest

from calib_core.calibration.verification import Verification


def _verification(disagreement_mm, three_sigma_mm, remaining_mm, tolerance_mm=1.0):
    return Verification(
        "t",
        np.array([remaining_mm, 0.0, 0.0]),
        np.zeros(3),
        np.full(3, 0.1),
        disagreement_mm,
        three_sigma_mm,
        0.3,
        8,
        tolerance_mm=tolerance_mm,
    )


def test_the_issues_case_disagrees():
    v = _verification(1.61, 1.68, 1.61)
    assert not v.agree and not v.within_tolerance and not v.ok
    assert "DISAGREE" in v.text and "OUTSIDE its 1 mm tolerance" in v.text


@pytest.mark.parametrize(
    "disagreement, three_sigma, remaining, agree, within",
    [
        (0.2, 0.5, 0.2, True, True),  # tight looks that agree, tool in tolerance
        (0.6, 0.5, 0.2, False, True),  # over their 3-sigma
        (0.9, 3.0, 0.3, True, True),  # loose looks: the tolerance (1 mm) caps what agreement means
        (1.2, 3.0, 0.3, False, True),  # beyond the tolerance although within 3-sigma
        (0.2, 0.5, 1.5, True, False),  # the looks agree but the tool is outside the tolerance
    ],
)
def test_agreement_is_capped_by_the_tolerance(disagreement, three_sigma, remaining, agree, within):
    v = _verification(disagreement, three_sigma, remaining)
    assert (v.agree, v.within_tolerance, v.ok) == (agree, within, agree and within)
