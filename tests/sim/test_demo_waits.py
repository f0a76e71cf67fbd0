"""A demo that waits too long says what it waited for, as one error line (a VideocalError), never a traceback."""

import pytest

from calib_core.errors import VideocalError


def test_a_wait_that_runs_out_names_what_it_waited_for_and_the_state(qapp):
    from videocal_sim.demo_operator import DemoTimeoutError, _wait

    with pytest.raises(DemoTimeoutError) as info:
        _wait(
            qapp, lambda: False, 0.05, "the controller link and the camera", lambda: "link not up; camera no frame yet"
        )
    assert isinstance(info.value, VideocalError) and isinstance(info.value, TimeoutError)
    assert (
        str(info.value)
        == "demo: waited 0.05 s for the controller link and the camera (link not up; camera no frame yet)"
    )
