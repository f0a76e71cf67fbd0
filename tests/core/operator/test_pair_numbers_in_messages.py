"""Messages name pairs by the numbers the table shows, not by their place in the solve."""

import numpy as np
import pytest

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.operator.core import OperatorCore
from calib_core.robot import solve_ik
from calib_core.solver.errors import named_points, point_label, points_label
from videocal_sim.sim_site import simulated_cell
from tests.core.operator.still_robot import frame_now, still_for

FEATURES = ("plate_top_left", "plate_top_right", "plate_bottom_left", "plate_bottom_right", "pin_tip", "boss_top_left")


def test_labels_follow_the_names_given_and_fall_back_to_positions():
    assert point_label(2) == "point 3" and points_label([0, 3]) == "points 1, 4"
    assert points_label(range(1500)) == "points 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12 and 1488 more"
    with named_points("pair", [9, 10, 14]):
        assert point_label(2) == "pair 14" and points_label([0, 2]) == "pairs 9, 14"
        assert point_label(5) == "point 6"  # beyond the names given: its position
    assert point_label(2) == "point 3"


@pytest.fixture(scope="module")
def picked():
    cell, site = simulated_cell(image_scale=0.5)
    core = OperatorCore(cell, site)
    q = solve_ik(core.robot, core.task.approach2base, core.cell.home_joints).q_deg
    still_for(core, joints_deg=q)
    frame_now(core)
    fixture = core.workcell.component(core.task.component)
    for _ in range(3):  # pairs 1 to 3 made and deleted: the set starts at 4
        core.picking.pick_model_point(fixture.name, "pin_tip", apply(fixture.item2world, fixture.features["pin_tip"]))
        core.picking.delete_pair()
    true_cam = site.bed.true_cam2world(q)
    for k, name in enumerate(FEATURES):
        p = apply(fixture.item2world, fixture.features[name])
        uv = project(apply(invert(true_cam), p[None]), core.intrinsics)[0] + (
            np.array([15.0, -12.0]) if k == 3 else 0.0
        )  # pair 7 mis-clicked
        core.picking.pick_model_point(fixture.name, name, p)
        core.picking.pick_image_point(uv)
        core.picking.accept_pair()
    return core


def test_a_failed_solve_names_the_mis_clicked_pair_by_its_table_number(picked):
    core = picked
    assert [p.number for p in core.session.pairs] == [4, 5, 6, 7, 8, 9]
    core.session.options.robust = False
    estimate = core.picking.calibrate()
    assert estimate.solution.status.value == "failed" and "pair 7 fits worst" in estimate.solution.reason, (
        estimate.solution.reason
    )
    core.session.options.robust = True
    estimate = core.picking.calibrate()
    assert any("pair 7 rejected as outliers" in w for w in estimate.solution.warnings), estimate.solution.warnings
