"""The prior as a measurement of a pose fit, and the points' 1-sigma a pose's covariance gives: each against finite
differences or a known answer."""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.look.edge_refinement import perturbed
from calib_core.look.locate_verdict import points_sigma_px
from calib_core.look.pose_prior import PosePrior


def _pose(rotvec, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    T[:3, 3] = t
    return T


def test_the_priors_normal_equations_are_its_residuals_linearised():
    """J^T W J and J^T W r from the prior match the residuals (the turn and the move from the prior, weighted by
    their 1-sigma) differentiated numerically through the fit's own step: to first order in the turn from the prior
    (2 deg here: within 1 %), and exactly where it matters, at the prior, where the steps end."""
    prior = PosePrior(_pose([0.1, -0.2, 0.3], [20.0, -10.0, 900.0]), sigma_mm=10.0, sigma_deg=3.0)
    pose = _pose([0.12, -0.18, 0.31], [26.0, -4.0, 915.0])
    W = np.diag([1.0 / np.radians(3.0) ** 2] * 3 + [1.0 / 10.0**2] * 3)

    def residual(T):
        turn = Rotation.from_matrix(T[:3, :3] @ prior.obj2cam[:3, :3].T).as_rotvec()
        return np.concatenate([turn, T[:3, 3] - prior.obj2cam[:3, 3]])

    J = np.empty((6, 6))
    for k in range(6):
        h = np.zeros(6)
        h[k] = 1e-6
        J[:, k] = (residual(perturbed(pose, h)) - residual(perturbed(pose, -h))) / 2e-6
    H, g = prior.normal_equations(pose)
    expected = J.T @ W @ J
    assert np.max(np.abs(H - expected)) < 0.02 * np.max(np.abs(expected))
    np.testing.assert_allclose(g, -J.T @ W @ residual(pose), rtol=0.02, atol=1e-6 * np.max(np.abs(g)))
    # steps on the prior alone land on it
    for _ in range(3):
        H, g = prior.normal_equations(pose)
        pose = perturbed(pose, np.linalg.solve(H, g))
    np.testing.assert_allclose(residual(pose), 0.0, atol=1e-9)


def test_the_points_sigma_of_a_move_across_the_sight_line_is_f_sigma_over_depth():
    """A point 1000 mm ahead, a 1-sigma of 2 mm in x and y: f 2 / 1000 px per axis, sqrt(2) of it as a distance."""
    camera = Intrinsics(800.0, 800.0, 320.0, 240.0, 640, 480)
    point = trimesh.Trimesh(vertices=np.zeros((1, 3)), faces=np.zeros((0, 3), dtype=int), process=False)
    pose = _pose([0.0, 0.0, 0.0], [0.0, 0.0, 1000.0])
    covariance = np.diag([0.0, 0.0, 0.0, 4.0, 4.0, 0.0])
    assert abs(points_sigma_px(point, pose, covariance, camera) - np.sqrt(2.0) * 800.0 * 2.0 / 1000.0) < 1e-3
    # a turn about the sight line moves a point 100 mm off it by 100 sigma: f 100 sigma / 1000
    off = trimesh.Trimesh(vertices=np.array([[100.0, 0.0, 0.0]]), faces=np.zeros((0, 3), dtype=int), process=False)
    turn = np.diag([0.0, 0.0, 1e-4, 0.0, 0.0, 0.0])
    assert abs(points_sigma_px(off, pose, turn, camera) - 800.0 * 100.0 * 1e-2 / 1000.0) < 1e-3


def test_a_look_with_no_reach_is_refused_with_the_reach_named():
    """A reach of 0 (or NaN) is a caller's mistake: an error that says which, not a division by zero deep in the
    fit."""
    import pytest

    from calib_core.errors import OperatorError
    from calib_core.look.locate import locate

    camera = Intrinsics(60.0, 60.0, 32.0, 24.0, 64, 48)
    box = trimesh.creation.box(extents=(40.0, 40.0, 40.0))
    image = np.zeros((48, 64, 3), np.uint8)
    for reach_mm, reach_deg, unit in ((0.0, 3.0, "mm"), (10.0, float("nan"), "deg")):
        with pytest.raises(OperatorError, match=f"reach must be above 0 {unit}"):
            locate(image, camera, box, _pose([0, 0, 0], [0, 0, 500.0]), reach_mm=reach_mm, reach_deg=reach_deg)


def test_a_pose_is_held_by_the_prior_within_three_times_its_reach_in_distance_and_in_turn():
    """Known answers at the bounds: 29 mm off a 10 mm reach is held, 31 mm is not (along any direction); 8.9 deg off a
    3 deg reach is held, 9.1 deg is not; either beyond is enough to leave it."""
    base = _pose([0.1, -0.2, 0.3], [20.0, -10.0, 900.0])
    prior = PosePrior(base, sigma_mm=10.0, sigma_deg=3.0)
    direction = np.array([2.0, -1.0, 2.0]) / 3.0
    for mm, held in ((29.0, True), (31.0, False)):
        moved = base.copy()
        moved[:3, 3] += mm * direction
        assert prior.holds(moved) is held
    for deg, held in ((8.9, True), (9.1, False)):
        turned = base.copy()
        turned[:3, :3] = Rotation.from_rotvec(np.radians(deg) * np.array([0.0, 0.6, 0.8])).as_matrix() @ base[:3, :3]
        assert prior.holds(turned) is held
    both = base.copy()
    both[:3, 3] += 5.0 * direction
    both[:3, :3] = Rotation.from_rotvec(np.radians(12.0) * np.array([1.0, 0.0, 0.0])).as_matrix() @ base[:3, :3]
    assert not prior.holds(both)
    assert prior.holds(both, sigmas=5.0)
