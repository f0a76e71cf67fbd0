"""A look at a part the cell says is not exactly its CAD: the same picks give a larger 1-sigma, and one over the
task's tolerance makes the verdict uncertain rather than ok (the residuals cannot show a form error)."""

import numpy as np

from calib_core.calibration.verdict import Verdict
from calib_core.operator.core import OperatorCore
from calib_core.robot import solve_ik
from videocal_sim.sim_site import simulated_cell
from tests.core.operator.perfect_operator import pick_all
from tests.core.operator.still_robot import frame_now, still_for


def _look(form_tolerance_mm: float):
    cell, site = simulated_cell(image_scale=0.5)
    core = OperatorCore(cell, site)
    cell.workcell.component(core.task.component).form_tolerance_mm = form_tolerance_mm
    q = solve_ik(core.robot, core.task.approach2base, cell.home_joints).q_deg
    still_for(core, joints_deg=q)
    frame_now(core)
    pick_all(core, site.bed, q)
    result = core.picking.calibrate()
    return result, core.session.result.verdict, core.session.result.context


def test_the_same_picks_are_less_certain_on_a_part_off_its_cad_and_uncertain_beyond_the_task_tolerance():
    exact, exact_verdict, exact_context = _look(0.0)
    loose, loose_verdict, loose_context = _look(0.3)
    rough, rough_verdict, _ = _look(3.0)
    assert exact_context.form_tolerance_mm == 0.0 and loose_context.form_tolerance_mm == 0.3
    np.testing.assert_allclose(loose.displacement_mm, exact.displacement_mm, atol=1e-9)  # the answer is the same
    assert np.linalg.norm(loose.std_displacement_mm) > 2.0 * np.linalg.norm(exact.std_displacement_mm)
    assert np.linalg.norm(loose.std_rotation_deg) > 2.0 * np.linalg.norm(exact.std_rotation_deg)
    assert exact_verdict.verdict is Verdict.OK
    assert np.linalg.norm(rough.std_displacement_mm) > 1.0  # the task's tolerance (1 mm)
    assert rough_verdict.verdict is Verdict.UNCERTAIN and "tolerance" in rough_verdict.text
