"""On a far link a frame's joint samples arrive up to the link's spread of delays after the frame: the frames
kept to fall back on span that lag, not a fixed count, so a click (or Find points) holds a frame that can be
judged even when a fast camera delivered dozens of frames since the newest joint sample."""

import numpy as np
import pytest

from calib_core.link.joint_history import ControllerClock, JointHistory
from calib_core.operator.observations import RECENT_FRAMES, Observations
from calib_core.connectors.frame import Frame


def _frame(index: int, t_s: float) -> Frame:
    return Frame(np.zeros((48, 64, 3), np.uint8), index, t_s)


def test_a_frame_with_its_samples_is_held_when_the_joint_stream_lags_a_second_behind_a_30_fps_camera():
    history = JointHistory()
    for t in np.arange(0.0, 3.0, 0.02):  # still robot, samples at 50 Hz up to 3.0 s
        history.add(float(t), np.zeros(6))
    clock = ControllerClock()  # a 1.5 s +-30 % link: samples arrive 1.05 to 1.5 s after they were sent
    for k, t in enumerate(np.arange(0.0, 3.0, 0.02)):
        clock.stamp(float(t) + 1.05 + 0.45 * (k % 2), float(t))
    assert clock.spread_s == pytest.approx(0.45, abs=1e-3)  # less its drift allowance
    obs = Observations(history, clock)
    for i, t in enumerate(np.arange(2.0, 4.0, 1 / 30)):  # frames up to 4.0 s: the newest 30 wait for samples
        obs.observe(_frame(i, float(t)))
    frame = obs.newest_usable()
    assert frame is not obs.latest and frame.t_host_s <= 3.0
    assert obs.stillness(frame).settled
    assert obs.hold().frame is frame


def test_near_the_kept_frames_are_the_fixed_few():
    history = JointHistory()
    obs = Observations(history)  # no spread: half a second of frames, at least RECENT_FRAMES of them
    for i, t in enumerate(np.arange(0.0, 10.0, 1 / 60)):
        obs.observe(_frame(i, float(t)))
    assert len(obs._recent) == max(RECENT_FRAMES, 31)
