"""The real-photo bench's measure of the annotation's own offset: known answers on made-up rows."""

import numpy as np
import pytest

from bench.photo_runs import FROM_TRUTH, Row
from bench.truth_checks import annotation_offset


def _rows(shift_px, scale, n=40, noise_px=1.0, width=640):
    rng = np.random.default_rng(3)
    out = []
    for _ in range(n):
        at = rng.uniform([40.0, 40.0], [600.0, 440.0])
        moved = np.asarray(shift_px) + [scale * (at[0] - width / 2.0), 0.0] + rng.normal(0.0, noise_px, 2)
        out.append(
            Row("lmo_dev", FROM_TRUTH, "k", "ok", 1.0, 3.0, 0.01, 1.0, 0.5, 100.0, 0.5, width, tuple(at), tuple(moved))
        )
    return out


def _numbers(line):
    import re

    return [float(x) for x in re.findall(r"[+-]?\d+\.\d+", line)]


def test_a_shift_every_view_shares_is_reported_with_its_standard_error():
    (line,) = annotation_offset(_rows((0.0, -1.5), 0.008))
    mean_u, error_u, mean_v, error_v, _, _, scale_percent = _numbers(line)
    assert mean_v == pytest.approx(-1.5, abs=3 * error_v) and abs(mean_v) > 5 * error_v
    assert abs(mean_u) < 3 * error_u + 0.3  # (the scale's mean over the image's width is near 0)
    assert scale_percent == pytest.approx(0.8, abs=0.15)
    assert error_v == pytest.approx(1.0 / np.sqrt(40), rel=0.3)


def test_views_not_ok_from_the_truth_and_other_priors_do_not_count():
    rows = _rows((0.0, 0.0), 0.0, n=10)
    others = [
        Row("lmo_dev", (10.0, 3.0), "k", "ok", 1.0, 3.0, 0.0, 1.0, 0.5, 100.0, 0.5, 640, (5.0, 5.0), (50.0, 50.0))
    ]
    lost = [
        Row("lmo_dev", FROM_TRUTH, "k", "uncertain", 1.0, 3.0, 0.0, 1.0, 0.5, 100.0, 0.5, 640, (5.0, 5.0), (50.0, 50.0))
    ]
    (line,) = annotation_offset(rows + others + lost)
    assert "10 views" in line and abs(_numbers(line)[2]) < 1.5
    assert annotation_offset(rows[:5]) == []  # too few to say
