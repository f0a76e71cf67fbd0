"""Dense linear algebra on tiny matrices (at most 12 x 12), compiled.

LAPACK through numba costs 5-15 us a call on matrices this small (workspace queries and
allocation); these loops cost well under a microsecond and keep a whole solve cheaper than
OpenCV's. Each routine is checked against numpy in ``tests/core/solver/test_small_linalg.py``.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def cholesky_factor(A, L):
    """Lower-triangular ``L`` with ``L L^T = A`` (A symmetric, p x p); False if not positive definite."""
    p = A.shape[0]
    for i in range(p):
        for j in range(i + 1):
            s = A[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            if i == j:
                if not s > 0.0:
                    return False
                L[i, i] = np.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
        for j in range(i + 1, p):
            L[i, j] = 0.0
    return True


@njit(cache=True)
def cholesky_substitute(L, g, x):
    """Solve ``L L^T x = g`` given the factor ``L``."""
    p = L.shape[0]
    for i in range(p):
        s = g[i]
        for k in range(i):
            s -= L[i, k] * x[k]
        x[i] = s / L[i, i]
    for i in range(p - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, p):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]


@njit(cache=True)
def cholesky_solve(A, g, x):
    """Solve ``A x = g`` for symmetric positive definite ``A``; False if not positive definite."""
    return cholesky_solve_in(A, g, x, np.empty_like(A))


@njit(cache=True)
def cholesky_solve_in(A, g, x, L):
    """:func:`cholesky_solve` with the factor's room ``L`` (p, p) given (a loop that solves many times makes it
    once)."""
    if not cholesky_factor(A, L):
        return False
    cholesky_substitute(L, g, x)
    return True


@njit(cache=True)
def spd_inverse(A, out):
    """``out = A^-1`` for symmetric positive definite ``A``; False if not positive definite."""
    p = A.shape[0]
    L = np.empty_like(A)
    if not cholesky_factor(A, L):
        return False
    e = np.zeros(p)
    x = np.empty(p)
    for j in range(p):
        e[:] = 0.0
        e[j] = 1.0
        cholesky_substitute(L, e, x)
        for i in range(p):
            out[i, j] = x[i]
    return True


@njit(cache=True)
def symmetric_eigenvalues(A):
    """Eigenvalues of a symmetric matrix, ascending (cyclic Jacobi rotations)."""
    p = A.shape[0]
    M = A.copy()
    for _ in range(50):
        off = 0.0
        diagonal = 0.0
        for i in range(p):
            diagonal += M[i, i] * M[i, i]
            for j in range(i + 1, p):
                off += M[i, j] * M[i, j]
        if off < 1e-30 * (diagonal + 2.0 * off + 1e-300):
            break
        for i in range(p):
            for j in range(i + 1, p):
                if M[i, j] == 0.0:
                    continue
                theta = (M[j, j] - M[i, i]) / (2.0 * M[i, j])
                t = np.sign(theta) / (abs(theta) + np.sqrt(theta * theta + 1.0)) if theta != 0.0 else 1.0
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                for k in range(p):
                    mki, mkj = M[k, i], M[k, j]
                    M[k, i] = c * mki - s * mkj
                    M[k, j] = s * mki + c * mkj
                for k in range(p):
                    mik, mjk = M[i, k], M[j, k]
                    M[i, k] = c * mik - s * mjk
                    M[j, k] = s * mik + c * mjk
    w = np.empty(p)
    for i in range(p):
        w[i] = M[i, i]
    return np.sort(w)


@njit(cache=True)
def inverse3(B, out):
    """``out = B^-1`` for a 3 x 3 matrix (cofactors); returns the determinant (0: singular, out untouched)."""
    det = (
        B[0, 0] * (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1])
        - B[0, 1] * (B[1, 0] * B[2, 2] - B[1, 2] * B[2, 0])
        + B[0, 2] * (B[1, 0] * B[2, 1] - B[1, 1] * B[2, 0])
    )
    if det == 0.0:
        return 0.0
    out[0, 0] = (B[1, 1] * B[2, 2] - B[1, 2] * B[2, 1]) / det
    out[0, 1] = (B[0, 2] * B[2, 1] - B[0, 1] * B[2, 2]) / det
    out[0, 2] = (B[0, 1] * B[1, 2] - B[0, 2] * B[1, 1]) / det
    out[1, 0] = (B[1, 2] * B[2, 0] - B[1, 0] * B[2, 2]) / det
    out[1, 1] = (B[0, 0] * B[2, 2] - B[0, 2] * B[2, 0]) / det
    out[1, 2] = (B[0, 2] * B[1, 0] - B[0, 0] * B[1, 2]) / det
    out[2, 0] = (B[1, 0] * B[2, 1] - B[1, 1] * B[2, 0]) / det
    out[2, 1] = (B[0, 1] * B[2, 0] - B[0, 0] * B[2, 1]) / det
    out[2, 2] = (B[0, 0] * B[1, 1] - B[0, 1] * B[1, 0]) / det
    return det
