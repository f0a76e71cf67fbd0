"""Every edit of a calibration is a command that checks itself when pushed: a refused edit raises the same error
whoever makes it, and changes nothing (no pair, no undo step)."""

import numpy as np
import pytest

from calib_core.calibration.commands import AddPoint3D, DeletePair, SetEnabled, SetPixel
from calib_core.calibration.correction_from_look import StoreLook
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.calibration.solve_options import SetOption
from calib_core.errors import UnknownNameError


def _session() -> CalibrationSession:
    s = CalibrationSession()
    s.set_target("fixture")
    return s


def _unchanged(s: CalibrationSession, pairs_before: list, undo_before: bool) -> bool:
    return list(s.pairs) == pairs_before and s.undo.can_undo == undo_before


def test_a_refused_pick_changes_nothing():
    s = _session()
    with pytest.raises(CalibrationError, match="pick the point on the model"):
        s.undo.push(SetPixel(s.pairs, None, (1.0, 2.0)))
    assert _unchanged(s, [], False)
    with pytest.raises(CalibrationError, match="pick on the target object 'fixture'"):
        s.undo.push(AddPoint3D(s.pairs, "rack", None, (0, 0, 0), target=s.target))
    assert _unchanged(s, [], False)
    number = s.undo.push(AddPoint3D(s.pairs, "fixture", "pin", (1, 2, 3), target=s.target)).number
    before = list(s.pairs)
    with pytest.raises(CalibrationError, match=f"pair {number} still needs its 2D point"):
        s.undo.push(AddPoint3D(s.pairs, "fixture", "corner", (0, 0, 0), target=s.target))
    assert _unchanged(s, before, True) and s.undo.undo() == "Pick 3D point " + before[0].label


def test_a_pick_of_the_waiting_pair_names_it():
    s = _session()
    number = s.undo.push(AddPoint3D(s.pairs, "fixture", "pin", (1, 2, 3), target=s.target)).number
    pick = s.undo.push(SetPixel(s.pairs, None, (5.0, 6.0)))
    assert pick.number == number and pick.label == f"Pick 2D point of pair {number}"
    assert s.pairs.get(number).pixel == (5.0, 6.0)


@pytest.mark.parametrize("command", [DeletePair, lambda pairs, n: SetEnabled(pairs, n, False)])
def test_an_edit_of_a_pair_that_is_not_there_is_refused(command):
    s = _session()
    with pytest.raises(UnknownNameError, match="no pair number 7"):
        s.undo.push(command(s.pairs, 7))
    assert not s.undo.can_undo


def test_an_option_set_to_the_value_it_has_is_no_edit():
    s = _session()
    s.undo.push(SetOption(s.options, "robust", s.options.robust))
    assert not s.undo.can_undo
    s.undo.push(SetOption(s.options, "robust", not s.options.robust))
    assert s.undo.can_undo


def test_a_store_without_a_result_says_calibrate_first():
    s = _session()
    with pytest.raises(CalibrationError, match="calibrate first"):
        s.undo.push(StoreLook(s, "task"))
    assert not s.undo.can_undo and np.size(s.corrections.tasks()) == 0
