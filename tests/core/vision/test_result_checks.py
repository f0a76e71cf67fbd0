"""The checks a vision result passes before it replaces the cell's camera model unasked."""

from types import SimpleNamespace

from calib_core.camera.intrinsics import Intrinsics
from calib_core.vision.result_checks import hand_eye_problems, intrinsics_problems, views_with_lost_corners
from calib_core.workcell.safety import SafetyLimits


def _intrinsics(f):
    return Intrinsics(f, f, 320.0, 240.0, 640, 480)


def test_intrinsics_over_a_pixel_or_another_lens_are_questioned():
    nominal = _intrinsics(800.0)
    assert intrinsics_problems(SimpleNamespace(rms_px=0.3, intrinsics=_intrinsics(808.0)), nominal) == []
    rms = intrinsics_problems(SimpleNamespace(rms_px=1.4, intrinsics=_intrinsics(808.0)), nominal)
    assert len(rms) == 1 and "1.40 px" in rms[0]
    lens = intrinsics_problems(SimpleNamespace(rms_px=0.3, intrinsics=_intrinsics(960.0)), nominal)
    assert len(lens) == 1 and "20 %" in lens[0]


def test_a_hand_eye_is_judged_against_the_measured_corner_noise_and_the_cell():
    good = SimpleNamespace(rms_px=0.4, warnings=[])
    assert hand_eye_problems(good, (0.8, 0.1), noise_px=0.2) == []
    assert "3 x the corner noise of 0.10 px" in hand_eye_problems(good, (0.8, 0.1), noise_px=0.05)[0]  # floor at 0.1 px
    far = hand_eye_problems(good, (44.8, 55.0), noise_px=0.2, limits=SafetyLimits())
    assert len(far) == 1 and "beyond the cell's stated model error" in far[0]
    told = SimpleNamespace(rms_px=45.0, warnings=["the views do not agree on one mounting (RMS 45.0 px): ..."])
    assert len(hand_eye_problems(told, (0.5, 0.1), noise_px=0.2)) == 1  # said once


def test_a_view_that_lost_corners_against_its_neighbours_is_flagged():
    assert views_with_lost_corners([44, 44, 30, 43, 44]) == {2: 44.0}
    assert views_with_lost_corners([24, 22, 23, 24]) == {}
    assert views_with_lost_corners([44]) == {}
