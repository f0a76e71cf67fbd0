"""The delay of a stamped stream (ROS 2's joint states), worked by hand."""

import pytest

from calib_core.link.arrival_delay import ArrivalDelay


def test_the_delay_is_the_median_arrival_minus_stamp_and_its_spread_four_mean_deviations():
    d = ArrivalDelay(recent=5)
    assert d.one_way_s() is None and d.spread_s == 0.0
    for stamp, arrival in ((100.0, 101.5), (100.1, 101.4), (100.2, 101.9), (100.3, 105.3)):  # 1.5, 1.3, 1.7, 5.0 s
        d.add(stamp, arrival)
    assert d.one_way_s() == pytest.approx(1.6)  # the median of 1.3, 1.5, 1.7, 5.0: one late sample does not move it
    assert d.spread_s == pytest.approx(4.0 * (0.3 + 0.1 + 0.1 + 3.4) / 4.0)
    for k in range(5):  # a window: the old ones leave
        d.add(200.0 + k, 200.2 + k)
    assert d.one_way_s() == pytest.approx(0.2) and d.spread_s == pytest.approx(0.0, abs=1e-9) and d.samples == 5


def test_a_sender_clock_ahead_shows_no_negative_delay_and_nonsense_is_not_a_sample():
    d = ArrivalDelay()
    d.add(10.0, 9.5)
    assert d.one_way_s() == 0.0
    d.add(float("nan"), 1.0)
    assert d.samples == 1
