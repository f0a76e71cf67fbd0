"""Every pose that puts three object points on three viewing rays (P3P), compiled: Grunert's
quartic as reviewed by Haralick et al. (IJCV 1994), its real roots bracketed between the
critical points and found by safeguarded Newton steps, each pose from the frames of the object's
triangle and of the camera's. OpenCV has P3P too, but calling it from compiled code is not possible, and its
Python call costs more than this whole kernel (the small-problem fast path runs it over every
triplet).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _cubic_real_roots(a, b, c, d, roots):
    """Real roots of ``a x^3 + b x^2 + c x + d`` (``a`` != 0) into ``roots`` (3,), ascending; how many."""
    p = b / a
    q = c / a
    r = d / a
    # x = y - p/3: y^3 + P y + Q = 0
    P = q - p * p / 3.0
    Q = 2.0 * p * p * p / 27.0 - p * q / 3.0 + r
    shift = -p / 3.0
    disc = Q * Q / 4.0 + P * P * P / 27.0
    if disc > 0.0:
        s = np.sqrt(disc)
        roots[0] = np.cbrt(-Q / 2.0 + s) + np.cbrt(-Q / 2.0 - s) + shift
        return 1
    if P == 0.0:
        roots[0] = shift
        return 1
    m = 2.0 * np.sqrt(-P / 3.0)
    theta = np.arccos(min(1.0, max(-1.0, 3.0 * Q / (P * m)))) / 3.0
    roots[0] = m * np.cos(theta) + shift
    roots[1] = m * np.cos(theta - 2.0 * np.pi / 3.0) + shift
    roots[2] = m * np.cos(theta - 4.0 * np.pi / 3.0) + shift
    roots[:3].sort()
    return 3


@njit(cache=True)
def _quartic(c, x):
    return (((c[0] * x + c[1]) * x + c[2]) * x + c[3]) * x + c[4]


@njit(cache=True)
def _real_quartic_roots(A4, A3, A2, A1, A0, roots):
    """Real roots of ``A4 v^4 + ... + A0`` into ``roots`` (4,); returns how many. Between the
    critical points (the derivative's real roots, in closed form) the quartic is monotonic: a
    sign change there brackets exactly one root, found by safeguarded Newton steps."""
    if abs(A4) < 1e-300:
        return 0
    c = np.array([1.0, A3 / A4, A2 / A4, A1 / A4, A0 / A4])
    bound = 1.0 + max(abs(c[1]), max(abs(c[2]), max(abs(c[3]), abs(c[4]))))  # Cauchy's bound
    crit = np.empty(3)
    nc = _cubic_real_roots(4.0, 3.0 * c[1], 2.0 * c[2], c[3], crit)
    edges = np.empty(5)
    edges[0] = -bound
    for k in range(nc):
        edges[k + 1] = min(max(crit[k], -bound), bound)
    edges[nc + 1] = bound
    count = 0
    for k in range(nc + 1):
        lo, hi = edges[k], edges[k + 1]
        flo, fhi = _quartic(c, lo), _quartic(c, hi)
        if flo == 0.0:
            if count == 0 or roots[count - 1] != lo:
                roots[count] = lo
                count += 1
            continue
        if flo * fhi > 0.0 or hi <= lo:
            continue
        x = 0.5 * (lo + hi)
        for _ in range(60):
            fx = _quartic(c, x)
            if fx == 0.0:
                break
            if (fx < 0.0) == (flo < 0.0):
                lo = x
            else:
                hi = x
            d = ((4.0 * c[0] * x + 3.0 * c[1]) * x + 2.0 * c[2]) * x + c[3]
            step = x - fx / d if d != 0.0 else 0.5 * (lo + hi)
            x = step if lo < step < hi else 0.5 * (lo + hi)
            if hi - lo <= 1e-15 * (1.0 + abs(x)):
                break
        roots[count] = x
        count += 1
    return count


@njit(cache=True)
def _triangle_frame(A, B, C, F):
    """``F`` (3, 3): columns an orthonormal frame of the triangle ``A B C`` (x along AB, z its normal)."""
    e1 = B - A
    e1 = e1 / np.sqrt(np.sum(e1 * e1))
    n = np.cross(e1, C - A)
    e3 = n / np.sqrt(np.sum(n * n))
    e2 = np.cross(e3, e1)
    for i in range(3):
        F[i, 0], F[i, 1], F[i, 2] = e1[i], e2[i], e3[i]


@njit(cache=True)
def _kabsch(Pw, X, R, t):
    """``R``, ``t`` with ``X_i = R Pw_i + t`` for three pairs (3, 3) of congruent triangles: the
    rotation between their frames (P3P makes the camera triangle the object's, to round-off)."""
    Fw = np.empty((3, 3))
    Fc = np.empty((3, 3))
    _triangle_frame(Pw[0], Pw[1], Pw[2], Fw)
    _triangle_frame(X[0], X[1], X[2], Fc)
    R[:, :] = Fc @ Fw.T
    t[:] = X[0] - R @ Pw[0]


@njit(cache=True)
def p3p(Pw, bearings, Rs, ts):
    """Poses ``(Rs[k], ts[k])`` (object to camera) that put ``Pw`` (3, 3) mm on the unit rays
    ``bearings`` (3, 3); up to four, into ``Rs`` (4, 3, 3) and ``ts`` (4, 3). Returns how many
    (0 for a degenerate triangle)."""
    j1, j2, j3 = bearings[0], bearings[1], bearings[2]
    a2 = np.sum((Pw[1] - Pw[2]) ** 2)
    b2 = np.sum((Pw[0] - Pw[2]) ** 2)
    c2 = np.sum((Pw[0] - Pw[1]) ** 2)
    if a2 < 1e-12 or b2 < 1e-12 or c2 < 1e-12:
        return 0
    ca = np.dot(j2, j3)
    cb = np.dot(j1, j3)
    cg = np.dot(j1, j2)
    amc = (a2 - c2) / b2
    apc = (a2 + c2) / b2
    A4 = (amc - 1.0) ** 2 - 4.0 * c2 / b2 * ca * ca
    A3 = 4.0 * (amc * (1.0 - amc) * cb - (1.0 - apc) * ca * cg + 2.0 * c2 / b2 * ca * ca * cb)
    A2 = 2.0 * (
        amc * amc
        - 1.0
        + 2.0 * amc * amc * cb * cb
        + 2.0 * (b2 - c2) / b2 * ca * ca
        - 4.0 * apc * ca * cb * cg
        + 2.0 * (b2 - a2) / b2 * cg * cg
    )
    A1 = 4.0 * (-amc * (1.0 + amc) * cb + 2.0 * a2 / b2 * cg * cg * cb - (1.0 - apc) * ca * cg)
    A0 = (1.0 + amc) ** 2 - 4.0 * a2 / b2 * cg * cg
    vs = np.empty(4)
    nv = _real_quartic_roots(A4, A3, A2, A1, A0, vs)
    X = np.empty((3, 3))
    count = 0
    for k in range(nv):
        v = vs[k]
        den = 2.0 * (cg - v * ca)
        if abs(den) < 1e-14:
            continue
        u = ((-1.0 + amc) * v * v - 2.0 * amc * cb * v + 1.0 + amc) / den
        q = 1.0 + v * v - 2.0 * v * cb
        if q <= 0.0 or u <= 0.0 or v <= 0.0:
            continue
        s1 = np.sqrt(b2 / q)
        X[0] = s1 * j1
        X[1] = u * s1 * j2
        X[2] = v * s1 * j3
        _kabsch(Pw, X, Rs[count], ts[count])
        count += 1
    return count
