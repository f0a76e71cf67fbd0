"""The compiled small-matrix routines against numpy's LAPACK on random matrices."""

import numpy as np
import pytest

from calib_core.solver.kernels.dlt import dlt_pose
from calib_core.solver.kernels.small_linalg import cholesky_solve, inverse3, spd_inverse, symmetric_eigenvalues
from scipy.spatial.transform import Rotation


@pytest.mark.parametrize("p", [3, 6, 8, 12])
def test_spd_routines_match_numpy(p):
    rng = np.random.default_rng(p)
    B = rng.normal(size=(p, p))
    A = B @ B.T + 0.1 * np.eye(p)
    g = rng.normal(size=p)
    x = np.empty(p)
    assert cholesky_solve(A, g, x)
    assert np.allclose(x, np.linalg.solve(A, g), rtol=1e-10)
    inv = np.empty((p, p))
    assert spd_inverse(A, inv)
    assert np.allclose(inv, np.linalg.inv(A), rtol=1e-9, atol=1e-12)
    assert np.allclose(symmetric_eigenvalues(A), np.linalg.eigvalsh(A), rtol=1e-10)


def test_indefinite_matrices_are_refused():
    A = np.diag([1.0, -1.0, 2.0])
    assert not cholesky_solve(A, np.ones(3), np.empty(3))
    assert not spd_inverse(A, np.empty((3, 3)))


def test_inverse3():
    B = np.random.default_rng(1).normal(size=(3, 3))
    out = np.empty((3, 3))
    assert inverse3(B, out) == pytest.approx(np.linalg.det(B))
    assert np.allclose(out, np.linalg.inv(B))
    assert inverse3(np.zeros((3, 3)), out) == 0.0


def test_dlt_recovers_an_exact_pose_and_refuses_coplanar_points():
    rng = np.random.default_rng(2)
    P = rng.uniform(-75, 75, (7, 3))
    R = Rotation.from_rotvec([0.3, -0.2, 0.4]).as_matrix()
    t = np.array([25.0, -15.0, 520.0])
    X = P @ R.T + t
    xy = X[:, :2] / X[:, 2:]
    R_out, t_out = np.empty((3, 3)), np.empty(3)
    assert dlt_pose(P, xy, R_out, t_out)
    assert np.allclose(R_out, R, atol=1e-10) and np.allclose(t_out, t, atol=1e-7)
    P[:, 2] = 0.0
    X = P @ R.T + t
    assert not dlt_pose(P, X[:, :2] / X[:, 2:], R_out, t_out)
