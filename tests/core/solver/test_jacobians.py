"""The analytic Jacobians of both camera models against central finite differences of the
residuals along Lowe's update; the paper's derivatives as printed are shown to be wrong."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.solver.kernels.camera_models import PAPER, PINHOLE, evaluate
from calib_core.solver.kernels.newton import rotate_by

from tests.core.solver.scenes import GRIPPER_CAMERA as CAM


def _step(R, t, f, delta):
    R_new = np.empty((3, 3))
    rotate_by(np.ascontiguousarray(delta[3:6]), R, R_new)
    f_new = f + (delta[6:8] if len(delta) == 8 else 0.0)
    return R_new, t + delta[:3], f_new


def _residuals(model, P, uv, R, t, f, focal, as_printed=False):
    p = 8 if focal else 6
    r = np.empty((len(P), 2))
    J = np.empty((len(P), 2, p))
    dist = CAM.dist_coeffs if model == PINHOLE else np.zeros(5)
    evaluate(model, P, uv, R, t, f[0], f[1], CAM.cx, CAM.cy, dist, focal, as_printed, r, J)
    return r, J


def _finite_difference(model, P, uv, R, t, f, focal, h=1e-6):
    p = 8 if focal else 6
    J = np.empty((len(P), 2, p))
    for k in range(p):
        d = np.zeros(p)
        d[k] = h
        rp, _ = _residuals(model, P, uv, *_step(R, t, f, d), focal)
        rm, _ = _residuals(model, P, uv, *_step(R, t, f, -d), focal)
        J[..., k] = -(rp - rm) / (2 * h)  # residual = observed - predicted
    return J


@pytest.fixture
def state():
    rng = np.random.default_rng(7)
    P = rng.uniform(-80, 80, (7, 3))
    uv = rng.uniform(0, 900, (7, 2))
    R = Rotation.from_rotvec([0.3, -0.2, 0.25]).as_matrix()
    return P, uv, R, np.array([35.0, -20.0, 450.0]), np.array([CAM.fu, CAM.fv])


@pytest.mark.parametrize("focal", [False, True])
def test_pinhole_jacobian_with_distortion_matches_finite_differences(state, focal):
    P, uv, R, t, f = state
    _, J = _residuals(PINHOLE, P, uv, R, t, f, focal)
    J_fd = _finite_difference(PINHOLE, P, uv, R, t, f, focal)
    assert np.max(np.abs(J - J_fd)) < 1e-6 * np.max(np.abs(J))


@pytest.mark.parametrize("focal", [False, True])
def test_paper_jacobian_corrected_matches_finite_differences(state, focal):
    P, uv, R, _, f = state
    d = np.array([700.0, 420.0, 450.0])  # d_x px, d_y px, d_z mm
    _, J = _residuals(PAPER, P, uv, R, d, f, focal)
    J_fd = _finite_difference(PAPER, P, uv, R, d, f, focal)
    assert np.max(np.abs(J - J_fd)) < 1e-6 * np.max(np.abs(J))


def test_paper_derivatives_as_printed_disagree_with_finite_differences(state):
    P, uv, R, _, f = state
    d = np.array([700.0, 420.0, 450.0])
    _, J_printed = _residuals(PAPER, P, uv, R, d, f, False, as_printed=True)
    J_fd = _finite_difference(PAPER, P, uv, R, d, f, False)
    column_error = np.max(np.abs(J_printed - J_fd), axis=(0, 1)) / np.max(np.abs(J_fd), axis=(0, 1))
    # Both misprints sit in c (every rotation and d_z column) and in dv/dd_z.
    assert column_error[2] > 0.1 and column_error[3:].max() > 0.1
    assert column_error[0] < 1e-6 and column_error[1] < 1e-6  # d_x, d_y columns are printed right


def test_incremental_rotation_is_exact_rodrigues():
    phi = np.array([0.3, -0.5, 0.2])
    out = np.empty((3, 3))
    rotate_by(phi, np.eye(3), out)
    assert np.allclose(out, Rotation.from_rotvec(phi).as_matrix(), atol=1e-15)
    rotate_by(np.zeros(3), np.eye(3), out)
    assert np.array_equal(out, np.eye(3))
