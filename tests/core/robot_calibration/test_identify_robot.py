"""The one identification driver (window, CLI and simulator all call it): the fit it makes from board
views is :func:`identify`'s own, and a component frame it cannot locate is named in the result's
warnings and counted out, never dropped silently."""

import numpy as np
import pytest

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.robot_calibration.identification import identify
from calib_core.robot_calibration.identify_robot import CellFrame, identify_robot
from calib_core.robot_calibration.observations import PoseView
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell, board_view_joints
from calib_core.workcell import load_workcell
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

SPEC = parse_board(DEFAULT_SPEC)


@pytest.fixture(scope="module")
def board_views():
    cell = load_workcell()
    bed = TestBed.create(cell, errors=RobotErrors.typical(0))
    board2base = board_in_cell(SPEC, cell, bed.model_robot)
    joints = board_view_joints(bed.model_robot, cell.home_joints_deg, SPEC, board2base, 30, seed=3)
    pts = SPEC.corners_mm()
    views = [
        PoseView(
            f"v{k}", np.asarray(q), pts, project(apply(invert(bed.true_cam2world(q)) @ board2base, pts), bed.intrinsics)
        )
        for k, q in enumerate(joints)
    ]
    return cell, bed, views


def test_a_component_not_seen_is_a_named_warning_and_the_fit_is_the_boards(board_views):
    cell, bed, views = board_views
    component = cell.components[0].name
    blank = np.full((bed.intrinsics.height, bed.intrinsics.width), 90, dtype=np.uint8)  # a frame with no edges
    told = []
    identified = identify_robot(
        bed.model_robot,
        bed.intrinsics,
        cell,
        views,
        [CellFrame(component, cell.home_joints_deg, blank, "look_at_nothing")],
        progress=lambda done, total, text: told.append((done, total)),
    )
    assert identified.board_views == len(views) and identified.cell_views == 0
    assert len(identified.not_located) == 1 and identified.not_located[0].startswith(
        f"look_at_nothing: {component} not located"
    )
    assert identified.not_located[0] in identified.result.warnings
    assert told == [(0, 2), (1, 2)]  # one component to locate, then the fit
    direct = identify(bed.model_robot, bed.intrinsics, views)
    assert identified.result.rms_px == pytest.approx(direct.rms_px, abs=1e-9)
    assert np.allclose(identified.result.board2base, direct.board2base, atol=1e-9)
