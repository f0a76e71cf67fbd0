"""BOP's pose errors checked two ways: known answers (a pure move, a symmetric object turned about its axis) and
the definition computed point by point."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.datasets.bop import symmetry_transforms
from calib_core.datasets.pose_errors import (
    MSPD_THRESHOLDS_PX,
    average_recall,
    mspd,
    mssd,
    rotation_error_deg,
    translation_error_mm,
)

K = Intrinsics(572.4, 573.6, 325.3, 242.0, 640, 480)
RNG = np.random.default_rng(3)
POINTS = RNG.uniform(-40, 40, (300, 3))


def _pose(rotvec_deg, t_mm):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T[:3, 3] = t_mm
    return T


def test_a_pure_move_is_its_length_in_space_and_a_pixel_shift_in_the_image():
    truth = _pose([10, 20, 5], [0, 0, 600])
    moved = truth.copy()
    moved[:3, 3] += [3.0, 4.0, 0.0]
    identity = symmetry_transforms({})
    assert mssd(moved, truth, POINTS, identity) == pytest.approx(5.0)
    assert translation_error_mm(moved, truth) == pytest.approx(5.0)
    assert rotation_error_deg(moved, truth) == pytest.approx(0.0, abs=1e-6)
    # by the definition: the largest pixel distance, point by point
    expected = np.max(np.linalg.norm(project_points(POINTS, moved, K) - project_points(POINTS, truth, K), axis=1))
    assert mspd(moved, truth, POINTS, identity, K) == pytest.approx(expected)


def test_a_turn_about_a_continuous_symmetry_costs_nothing_and_about_another_axis_it_does():
    cylinder = np.column_stack(
        [
            30 * np.cos(np.linspace(0, 2 * np.pi, 200)),
            30 * np.sin(np.linspace(0, 2 * np.pi, 200)),
            np.linspace(-50, 50, 200),
        ]
    )
    syms = symmetry_transforms({"symmetries_continuous": [{"axis": [0, 0, 1], "offset": [0, 0, 0]}]})
    assert len(syms) == int(np.ceil(np.pi / 0.01))
    truth = _pose([30, 0, 0], [10, 0, 700])
    turned = truth @ _pose([0, 0, 37], [0, 0, 0])
    # the sampled symmetries are 2 pi / 315 apart: a point 30 mm from the axis is at most 0.3 mm from one of them
    assert mssd(turned, truth, cylinder, syms) < 0.31
    assert mssd(turned, truth, cylinder, symmetry_transforms({})) > 18.0
    tilted = truth @ _pose([5, 0, 0], [0, 0, 0])
    assert mssd(tilted, truth, cylinder, syms) > 4.0


def test_a_discrete_symmetry_with_an_offset_maps_the_model_onto_itself():
    # a box 80 x 40 x 20 centred at (10, 0, 0) in its frame: a half turn about the x axis through its centre
    half_turn = np.eye(4)
    half_turn[:3, :3] = np.diag([1.0, -1.0, -1.0])
    syms = symmetry_transforms({"symmetries_discrete": [half_turn.reshape(-1).tolist()]})
    corners = np.array([[x, y, z] for x in (-30, 50) for y in (-20, 20) for z in (-10, 10)], float)
    truth = _pose([0, 20, 0], [0, 0, 500])
    assert mssd(truth @ half_turn, truth, corners, syms) == pytest.approx(0.0, abs=1e-9)


def test_average_recall_counts_failures_as_misses():
    errors = np.array([1.0, 7.0, 12.0, np.inf])
    # 5 px: 1 of 4; 10 px: 2; 15..50 px: 3
    assert average_recall(errors, MSPD_THRESHOLDS_PX) == pytest.approx((1 + 2 + 3 * 8) / 40)
