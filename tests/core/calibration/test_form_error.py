"""A part that is not its CAD: the pose's covariance from features lying off their CAD positions, checked against
a Monte Carlo of solves on features moved at random, and carried into a look's 1-sigma."""

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.calibration.form_error import form_error_covariance
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.solver.solve import solve_pose

LENS = Intrinsics(1000.0, 1000.0, 640.0, 480.0, 1280, 960)
POINTS = np.array(
    [
        [-60.0, -40.0, 0.0],
        [60.0, -40.0, 0.0],
        [60.0, 40.0, 0.0],
        [-60.0, 40.0, 0.0],
        [0.0, 0.0, 25.0],
        [-30.0, 10.0, 10.0],
    ]
)
OBJ2CAM = make_transform(Rotation.from_euler("xyz", [170.0, 8.0, -5.0], degrees=True).as_matrix(), [10.0, -5.0, 300.0])


def _difference(start, moved):  # the solver's (dt mm, phi rad)
    return np.r_[moved[:3, 3] - start[:3, 3], Rotation.from_matrix(moved[:3, :3] @ start[:3, :3].T).as_rotvec()]


def test_the_covariance_matches_solves_on_features_moved_at_random():
    tolerance = 0.5
    pixels = project_points(POINTS, OBJ2CAM, LENS)  # the image shows the real part; the solve is given the CAD
    rng = np.random.default_rng(7)
    offsets = []
    for _ in range(400):
        real = POINTS + rng.normal(0.0, tolerance, POINTS.shape)
        seen = project_points(real, OBJ2CAM, LENS)
        solution = solve_pose(POINTS, seen, LENS, prior=OBJ2CAM, sigma_px=0.5)
        offsets.append(_difference(OBJ2CAM, solution.obj2cam))
    sampled = np.cov(np.array(offsets).T)
    predicted = form_error_covariance(OBJ2CAM, POINTS, LENS, tolerance)
    # 400 samples: each standard deviation within about 10 % of the prediction
    np.testing.assert_allclose(np.sqrt(np.diag(sampled)), np.sqrt(np.diag(predicted)), rtol=0.15)
    assert pixels.shape == (6, 2)


def test_it_grows_with_the_square_of_the_tolerance_and_vanishes_without_one():
    one = form_error_covariance(OBJ2CAM, POINTS, LENS, 1.0)
    np.testing.assert_allclose(form_error_covariance(OBJ2CAM, POINTS, LENS, 0.3), 0.09 * one, rtol=1e-9, atol=1e-15)
    assert not form_error_covariance(OBJ2CAM, POINTS, LENS, 0.0).any()
    assert not form_error_covariance(OBJ2CAM, POINTS[:3], LENS, 1.0).any()
    np.testing.assert_allclose(one, one.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(one) > -1e-12)
