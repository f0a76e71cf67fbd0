"""The joint history: joints at a frame's capture time (known answers) and whether the robot had
settled before it, from the samples alone."""

import numpy as np
import pytest

from calib_core.link.joint_history import ControllerClock, JointHistory, SettleRule


def _ramp(history, t0, t1, q0, q1, rate_hz=50.0):
    for t in np.arange(t0, t1 + 1e-9, 1.0 / rate_hz):
        w = (t - t0) / (t1 - t0)
        history.add(t, (1 - w) * np.asarray(q0, float) + w * np.asarray(q1, float))


def test_joints_between_two_samples_are_interpolated_and_the_gap_is_kept():
    h = JointHistory()
    h.add(10.0, [0.0, 10.0])
    h.add(10.02, [1.0, 10.0])
    at = h.joints_at(10.005)
    np.testing.assert_allclose(at.joints_deg, [0.25, 10.0])
    assert at.stamp_gap_s == pytest.approx(0.005)
    assert h.joints_at(10.02 + 0.3) is None  # beyond max_gap_s: unknown, not extrapolated
    h.add(10.01, [5.0, 5.0])  # older than the newest: dropped, the history stays in order
    np.testing.assert_allclose(h.joints_at(10.02).joints_deg, [1.0, 10.0])


def test_a_robot_is_settled_only_after_holding_still_for_the_set_time():
    h = JointHistory(rule=SettleRule(speed_deg_s=0.5, hold_s=0.3), joint_names=["a", "b"])
    _ramp(h, 0.0, 1.0, [0, 0], [0, 20])  # b at 20 deg/s
    _ramp(h, 1.02, 2.0, [0, 20], [0, 20])  # then still
    moving = h.stillness(0.5)
    assert not moving.settled and moving.joint == 1 and moving.speed_deg_s == pytest.approx(20.0, rel=1e-6)
    assert "b at 20.00 deg/s" in moving.reason
    early = h.stillness(1.2)  # still since the last moving sample at 1.0 s: 0.2 s only
    assert not early.settled and early.still_for_s == pytest.approx(0.2, abs=1e-6)
    late = h.stillness(1.5)
    assert late.settled and late.still_for_s == pytest.approx(0.5, abs=1e-6)


def test_encoder_noise_below_the_threshold_is_still_and_a_gap_is_not():
    rng = np.random.default_rng(0)
    h = JointHistory(rule=SettleRule(speed_deg_s=0.5, hold_s=0.3, max_gap_s=0.1))
    for k in range(50):
        h.add(k * 0.02, rng.normal(0.0, 0.001, 6))  # 1 mdeg noise: ~0.07 deg/s between samples
    assert h.stillness(0.98).settled
    h.add(1.5, np.zeros(6))  # 0.52 s without a sample
    h.add(1.52, np.zeros(6))
    gap = h.stillness(1.52)
    assert not gap.settled and "may have moved unseen" in gap.reason
    h.forget(1.6)
    assert not h.stillness(1.6).settled and "link dropped" in h.stillness(1.6).reason


def test_jittered_sample_times_and_quantised_joints_do_not_make_a_still_robot_move():
    """Samples that arrive in bursts (0.1 ms apart) with a last-digit flicker of the controller's
    0.0001 deg: a pairwise speed would be 1 deg/s; the band test sees a still robot."""
    rng = np.random.default_rng(1)
    h = JointHistory(rule=SettleRule(speed_deg_s=0.5, hold_s=0.3))
    t = 0.0
    for _ in range(60):
        t += rng.choice([0.0001, 0.02, 0.039])
        h.add(t, np.round(rng.choice([0.0, 0.0001], 6), 4))
    assert h.stillness(t).settled


def test_the_controller_clock_removes_the_arrival_delay():
    """Known answer: sent every 20 ms on the controller's clock (offset 100 s), delayed on arrival by
    5 to 80 ms; the stamps are the send times plus the smallest delay seen (5 ms)."""
    rng = np.random.default_rng(2)
    clock = ControllerClock(drift_allowance=0.0)
    sent = np.arange(200) * 0.02
    delays = rng.uniform(0.005, 0.08, 200)
    delays[3] = 0.005
    stamps = [clock.stamp(100.0 + s + d, s) for s, d in zip(sent, delays)]
    np.testing.assert_allclose(stamps[3:], 100.0 + sent[3:] + 0.005, atol=1e-12)
    assert clock.delay_s == pytest.approx(delays[-1] - 0.005)
    clock.stamp(200.0, 1.0)  # the controller's clock went back: a restart, the estimate starts again
    assert clock.restarts == 1 and clock.offset_s == pytest.approx(199.0)


def test_a_far_links_spread_of_delays_is_measured_and_widens_the_stillness_it_takes():
    """A frame stamped on arrival that crossed a far link may show the robot up to the link's spread of delays
    earlier than its stamp says (on the joints' time base): the robot must have been still that much longer."""
    clock = ControllerClock()
    for t_c, delay in ((0.0, 1.2), (0.02, 1.5), (0.04, 1.3), (0.06, 1.9)):  # 1.5 s +-30 % one way
        clock.stamp(100.0 + t_c + delay, t_c)
    assert clock.spread_s == pytest.approx(0.7, abs=1e-3)  # the slowest over the fastest (less the drift allowance)
    clock.stamp(100.0 + 20.0 + 1.2, 20.0)  # ten seconds on: the old delays have aged out of the window
    assert clock.spread_s == pytest.approx(0.0, abs=1e-2)
    h = JointHistory(rule=SettleRule(speed_deg_s=0.5, hold_s=0.3), joint_names=["a"])
    _ramp(h, 0.0, 1.0, [0], [20])  # moving until t = 1
    _ramp(h, 1.02, 3.0, [20], [20])  # still after
    assert h.stillness(1.4).settled  # a near link: 0.3 s of stillness before the frame are enough
    far = h.stillness(1.4, margin_s=0.5)  # its content may be from t = 0.9: the robot was moving then
    assert not far.settled and "0.50 s older than it says" in far.reason and far.joint == 0
    assert h.stillness(1.9, margin_s=0.5).settled
    # a frame newer than the newest sample by more than the gap allowed, less than the gap plus the spread: pending,
    # not "pose unknown" (the samples of its time are on their way)
    assert h.stillness(3.5).reason.startswith("no joint sample") and not h.stillness(3.5).pending
    assert h.stillness(3.5, margin_s=0.5).pending
