"""Compiled direct linear transform (DLT): a starting pose from six or more non-coplanar points.

Cheap enough to seed every solve with many points, where SQPnP would cost as much as the
whole refinement; the Newton iterations then remove its algebraic bias. Falls back (returns
False) on coplanar or degenerate points, where the DLT has no unique answer.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from calib_core.solver.kernels.small_linalg import cholesky_factor, cholesky_substitute, inverse3


# The second-smallest eigenvalue of the (normalised) DLT system must exceed this fraction of its
# trace: below it the null space is not one-dimensional (coplanar points, too few distinct rays).
_GAP = 1e-9


@njit(cache=True)
def _smallest_eigenvector(M):
    """Unit eigenvector (12,) of the smallest eigenvalue of the PSD matrix ``M`` by inverse
    iteration (a few Cholesky solves cost far less than an eigen-decomposition); None if
    that eigenvalue is not well separated (degenerate points)."""
    p = M.shape[0]
    trace = 0.0
    for i in range(p):
        trace += M[i, i]
    A = M.copy()
    for i in range(p):
        A[i, i] += 1e-13 * trace
    L = np.empty((p, p))
    if not cholesky_factor(A, L):
        return None
    x = np.ones(p) / np.sqrt(p)
    y = np.empty(p)
    for _ in range(8):
        cholesky_substitute(L, x, y)
        x[:] = y / np.sqrt(np.sum(y * y))
    rayleigh = x @ (M @ x)
    if not rayleigh < 1e-2 * trace / p:
        return None
    # The next eigenvalue, by the same iteration on M with x shifted out of the way: coplanar or
    # otherwise degenerate points leave it near zero too, and then the pose is not determined.
    for i in range(p):
        for k in range(p):
            A[i, k] = M[i, k] + trace * x[i] * x[k]
        A[i, i] += 1e-13 * trace
    if not cholesky_factor(A, L):
        return None
    z = np.ones(p) / np.sqrt(p)
    for _ in range(8):
        cholesky_substitute(L, z, y)
        z[:] = y / np.sqrt(np.sum(y * y))
    if not z @ (M @ z) > _GAP * trace:
        return None
    return x


@njit(cache=True)
def _nearest_rotation(B):
    """The rotation nearest to ``B`` (3, 3, positive determinant) by Newton's polar iteration."""
    R = B.copy()
    inv = np.empty((3, 3))
    for _ in range(30):
        inverse3(R, inv)
        Rn = 0.5 * (R + inv.T)
        if np.max(np.abs(Rn - R)) < 1e-15:
            return Rn
        R = Rn
    return R


@njit(cache=True)
def dlt_pose(P, xy, R_out, t_out):
    """Pose ``(R_out (3, 3), t_out (3,) mm)`` from points ``P`` (n, 3) mm and their
    normalized undistorted image coordinates ``xy`` (n, 2); False when no usable pose."""
    n = P.shape[0]
    if n < 6:
        return False
    c = np.zeros(3)
    for i in range(n):
        for k in range(3):
            c[k] += P[i, k] / n
    s = 0.0
    for i in range(n):
        s += (P[i, 0] - c[0]) ** 2 + (P[i, 1] - c[1]) ** 2 + (P[i, 2] - c[2]) ** 2
    s = np.sqrt(s / n)
    if not s > 0.0:
        return False
    M = np.zeros((12, 12))
    a = np.zeros(12)
    q = np.empty(4)
    for i in range(n):
        for k in range(3):
            q[k] = (P[i, k] - c[k]) / s
        q[3] = 1.0
        for row in range(2):
            a[:] = 0.0
            for k in range(4):
                a[4 * row + k] = q[k]
                a[8 + k] = -xy[i, row] * q[k]
            for u in range(12):
                for v in range(12):
                    M[u, v] += a[u] * a[v]
    v = _smallest_eigenvector(M)
    if v is None:
        return False
    m = np.empty((3, 4))
    for k in range(12):
        m[k // 4, k % 4] = v[k]
    if m[2, 3] < 0.0:  # the centroid must lie in front of the camera
        m = -m
    B = np.ascontiguousarray(m[:, :3])
    det = (
        B[0, 0] * (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1])
        - B[0, 1] * (B[1, 0] * B[2, 2] - B[1, 2] * B[2, 0])
        + B[0, 2] * (B[1, 0] * B[2, 1] - B[1, 1] * B[2, 0])
    )
    if not det > 0.0:  # a reflection: the points do not determine a camera
        return False
    lam = det ** (1.0 / 3.0)
    R_out[:, :] = _nearest_rotation(B / lam)
    for k in range(3):
        t_out[k] = m[k, 3] / lam * s - (R_out[k, 0] * c[0] + R_out[k, 1] * c[1] + R_out[k, 2] * c[2])
    for i in range(n):
        z = R_out[2, 0] * P[i, 0] + R_out[2, 1] * P[i, 1] + R_out[2, 2] * P[i, 2] + t_out[2]
        if not z > 0.0:
            return False
    return True


@njit(cache=True, parallel=True)
def dlt_pose_batch(P, xy, R_out, t_out, ok):
    """:func:`dlt_pose` for each of ``b`` problems: ``P`` (b, n, 3), ``xy`` (b, n, 2)."""
    for i in prange(P.shape[0]):
        ok[i] = dlt_pose(P[i], xy[i], R_out[i], t_out[i])
