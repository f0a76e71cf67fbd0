"""A newer solver that reaches the recorded minimum by another path agrees to round-off; anything
larger is a difference."""

from calib_core.recording.replay import ReplayedSolve


def _replayed(dt, dr, drms, status="ok"):
    return ReplayedSolve(
        1, {"status": "ok"}, {"status": status}, status == "ok" and dt == dr == drms == 0.0, dt, dr, drms
    )


def test_round_off_is_equivalent_and_a_real_change_is_not():
    assert _replayed(0.0, 0.0, 0.0).agree
    same = _replayed(7e-12, 1e-12, 5e-14)
    assert same.equivalent and not same.agree
    assert not _replayed(2e-6, 0.0, 0.0).equivalent
    assert not _replayed(0.0, 1e-8, 0.0).equivalent
    assert not _replayed(1e-12, 0.0, 0.0, status="failed").equivalent
