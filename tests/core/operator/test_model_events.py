"""The core's events say what changed and only when it did: joints on a change, not on every
sample; solve options through the undo stack with their own event."""

from calib_core.calibration.solve_options import SetOption
import numpy as np

from calib_core.operator.core import OperatorCore
from videocal_sim.sim_site import simulated_cell
from tests.core.operator.still_robot import sample, still_for


def test_joints_changed_only_when_the_joints_change():
    cell, site = simulated_cell(image_scale=0.25)
    core = OperatorCore(cell, site)
    seen = []
    core.arm.joints_changed.connect(lambda q: seen.append(np.array(q)))
    q = np.array(cell.home_joints, dtype=float) + 1.0
    t = still_for(core, 0.5, joints_deg=q)  # 26 samples of a still robot
    assert len(seen) == 1 and np.array_equal(seen[0], q)
    q2 = q.copy()
    q2[0] += 0.001
    sample(core, q2, t + 0.02)
    assert len(seen) == 2 and np.allclose(seen[-1], q2)


def test_solve_options_are_undoable_and_announced():
    cell, site = simulated_cell(image_scale=0.25)
    core = OperatorCore(cell, site)
    changes = []
    core.session.options.changed.connect(lambda name, value: changes.append((name, value)))
    core.session.undo.push(SetOption(core.session.options, "robust", True))
    core.session.undo.push(SetOption(core.session.options, "robust", True))  # no change: no event, no undo entry
    assert core.session.options.robust and changes == [("robust", True)]
    assert core.undo() == "Use the robust option"
    assert not core.session.options.robust and changes[-1] == ("robust", False)
    core.redo()
    assert core.session.options.robust
