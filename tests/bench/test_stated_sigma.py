"""The real-photo bench's check of the stated 1-sigma: known answers on made-up rows and poses."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from bench.photo_runs import FROM_TRUTH, RUNS, TRUTH_REACH, Row
from bench.truth_checks import stated_sigma, with_start_agreement
from calib_core.camera.intrinsics import Intrinsics


def _row(prior, status="ok", mspd_px=4.0, sigma=2.0, apart=None, apart_sigma=None, width=640, reach=None):
    return Row(
        "lmo_dev",
        prior,
        "k",
        status,
        1.0,
        mspd_px,
        1.0,
        1.0,
        1.0,
        100.0,
        0.5,
        width,
        points_sigma_px=sigma,
        apart_px=apart,
        apart_sigma_px=apart_sigma,
        reach=reach,
    )


def test_two_answers_apart_by_their_combined_sigma_give_one_and_the_annotation_its_own_ratio():
    rows = [_row((10.0, 3.0), mspd_px=6.0, sigma=2.0, apart=a, apart_sigma=2.0) for a in (1.0, 2.0, 2.0, 3.0, 8.0)]
    rows.append(_row((10.0, 3.0), status="uncertain", apart=None))  # not from both: left out
    (line,) = stated_sigma(rows)[2:]
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[:3] == ["lmo_dev", "10 mm / 3 deg", "5"]
    assert cells[3].startswith("1.00, ") and float(cells[3].split(", ")[1]) == pytest.approx(
        3.0
    )  # ratios 0.5, 1, 1, 1.5, 4: the 90th percentile 1.5 + 0.6 * 2.5
    assert cells[4] == "1"  # 8 px at 2 px
    assert cells[5] == "3.00, 3.00" and cells[6] == "0"


def test_a_photo_twice_as_wide_gives_the_same_ratios():
    narrow = [_row((30.0, 10.0), mspd_px=6.0, sigma=2.0, apart=2.0, apart_sigma=2.0) for _ in range(5)]
    wide = [_row((30.0, 10.0), mspd_px=12.0, sigma=4.0, apart=4.0, apart_sigma=4.0, width=1280) for _ in range(5)]
    assert stated_sigma(narrow)[2:] == stated_sigma(wide)[2:]
    assert stated_sigma(narrow[:4]) == []  # too few views to say


def test_each_answer_is_measured_from_the_answer_started_at_the_truth():
    """Known answers: each run's answer 1 mm further right at 600 mm (1 px a mm); every ``ok`` answer from a prior off
    the truth is measured from the one started at the truth searching :data:`TRUTH_REACH`, not from the one searching a
    robot's reach, and neither of those from itself."""
    camera = Intrinsics(600.0, 600.0, 320.0, 240.0, 640, 480)
    points = np.array([[0.0, 0.0, 0.0], [30.0, 0.0, 0.0], [0.0, 30.0, 0.0]])
    at = {}
    for (prior, reach), x in zip(RUNS, (0.0, 1.0, 2.0, 3.0, 4.0)):
        pose = np.eye(4)
        pose[:3, 3] = [x, 0.0, 600.0]
        at[(prior, reach)] = pose
    assert RUNS[3] == (FROM_TRUTH, TRUTH_REACH)
    rows = [_row(prior, sigma=1.5 if prior == FROM_TRUTH else 2.0, reach=reach) for prior, reach in RUNS]
    rows[1] = _row(RUNS[1][0], status="uncertain")
    view = SimpleNamespace(intrinsics=camera)
    out = with_start_agreement(rows, at, points, np.eye(4)[None], view)
    assert out[0].apart_px == pytest.approx(3.0) and out[0].apart_sigma_px == pytest.approx(2.5)
    assert out[1].apart_px is None  # not ok
    assert out[2].apart_px == pytest.approx(1.0)
    assert out[3].apart_px is None and out[4].apart_px is None  # the answers started at the truth itself
    rows[3] = _row(FROM_TRUTH, status="not found", reach=TRUTH_REACH)
    assert all(r.apart_px is None for r in with_start_agreement(rows, at, points, np.eye(4)[None], view))
