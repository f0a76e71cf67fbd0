"""Every pose that puts three object points on three viewing rays (P3P), compiled: Grunert's
quartic as reviewed by Haralick et al. (IJCV 1994), its real roots bracketed between the
critical points and found by safeguarded Newton steps, each pose from the frames of the object's
triangle and of the camera's. OpenCV has P3P too, but calling it from compiled code is not possible, and its
Python call costs more than this whole kernel (the small-problem fast path runs it over every
triplet). Scalar arithmetic throughout: a small array made, or a BLAS call, per root costs more than the root.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _cubic_real_roots(a, b, c, d):
    """Real roots of ``a x^3 + b x^2 + c x + d`` (``a`` != 0), ascending: ``(count, x0, x1, x2)``."""
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
        return 1, np.cbrt(-Q / 2.0 + s) + np.cbrt(-Q / 2.0 - s) + shift, 0.0, 0.0
    if P == 0.0:
        return 1, shift, 0.0, 0.0
    m = 2.0 * np.sqrt(-P / 3.0)
    theta = np.arccos(min(1.0, max(-1.0, 3.0 * Q / (P * m)))) / 3.0
    x0 = m * np.cos(theta) + shift
    x1 = m * np.cos(theta - 2.0 * np.pi / 3.0) + shift
    x2 = m * np.cos(theta - 4.0 * np.pi / 3.0) + shift
    # sort three
    if x0 > x1:
        x0, x1 = x1, x0
    if x1 > x2:
        x1, x2 = x2, x1
    if x0 > x1:
        x0, x1 = x1, x0
    return 3, x0, x1, x2


@njit(cache=True)
def _quartic(c1, c2, c3, c4, x):
    """The monic quartic ``x^4 + c1 x^3 + c2 x^2 + c3 x + c4``."""
    return (((x + c1) * x + c2) * x + c3) * x + c4


@njit(cache=True)
def _bracketed_root(c1, c2, c3, c4, lo, hi, flo):
    """The one root of the monic quartic in ``[lo, hi]``, where it is monotonic and changes sign
    (``flo``: its value at ``lo``): safeguarded Newton steps."""
    x = 0.5 * (lo + hi)
    for _ in range(60):
        fx = _quartic(c1, c2, c3, c4, x)
        if fx == 0.0:
            break
        if (fx < 0.0) == (flo < 0.0):
            lo = x
        else:
            hi = x
        d = ((4.0 * x + 3.0 * c1) * x + 2.0 * c2) * x + c3
        step = x - fx / d if d != 0.0 else 0.5 * (lo + hi)
        x = step if lo < step < hi else 0.5 * (lo + hi)
        if hi - lo <= 1e-15 * (1.0 + abs(x)):
            break
    return x


@njit(cache=True)
def _real_quartic_roots(A4, A3, A2, A1, A0, roots):
    """Real roots of ``A4 v^4 + ... + A0`` into ``roots`` (4,); returns how many. Between the
    critical points (the derivative's real roots, in closed form) the quartic is monotonic: a
    sign change there brackets exactly one root, found by safeguarded Newton steps."""
    if abs(A4) < 1e-300:
        return 0
    c1, c2, c3, c4 = A3 / A4, A2 / A4, A1 / A4, A0 / A4
    bound = 1.0 + max(abs(c1), max(abs(c2), max(abs(c3), abs(c4))))  # Cauchy's bound
    nc, k0, k1, k2 = _cubic_real_roots(4.0, 3.0 * c1, 2.0 * c2, c3)
    # the intervals' edges: -bound, the critical points (clipped), bound
    e0 = -bound
    e1 = min(max(k0, -bound), bound)
    e2 = min(max(k1, -bound), bound) if nc == 3 else bound
    e3 = min(max(k2, -bound), bound) if nc == 3 else bound
    e4 = bound
    count = 0
    for k in range(nc + 1):
        if k == 0:
            lo, hi = e0, e1
        elif k == 1:
            lo, hi = e1, e2
        elif k == 2:
            lo, hi = e2, e3
        else:
            lo, hi = e3, e4
        flo, fhi = _quartic(c1, c2, c3, c4, lo), _quartic(c1, c2, c3, c4, hi)
        if flo == 0.0:
            if count == 0 or roots[count - 1] != lo:
                roots[count] = lo
                count += 1
            continue
        if flo * fhi > 0.0 or hi <= lo:
            continue
        roots[count] = _bracketed_root(c1, c2, c3, c4, lo, hi, flo)
        count += 1
    return count


@njit(cache=True)
def _unit(x, y, z):
    n = np.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n


@njit(cache=True)
def _triangle_frame(A, B, C, F):
    """``F`` (3, 3): columns an orthonormal frame of the triangle ``A B C`` (rows of 3; x along AB, z its normal)."""
    e1x, e1y, e1z = _unit(B[0] - A[0], B[1] - A[1], B[2] - A[2])
    cx, cy, cz = C[0] - A[0], C[1] - A[1], C[2] - A[2]
    e3x, e3y, e3z = _unit(e1y * cz - e1z * cy, e1z * cx - e1x * cz, e1x * cy - e1y * cx)
    F[0, 0], F[1, 0], F[2, 0] = e1x, e1y, e1z
    F[0, 1], F[1, 1], F[2, 1] = e3y * e1z - e3z * e1y, e3z * e1x - e3x * e1z, e3x * e1y - e3y * e1x
    F[0, 2], F[1, 2], F[2, 2] = e3x, e3y, e3z


@njit(cache=True)
def _kabsch(Pw, X, Fw, Fc, R, t):
    """``R``, ``t`` with ``X_i = R Pw_i + t`` for three pairs (3, 3) of congruent triangles: the
    rotation between their frames (P3P makes the camera triangle the object's, to round-off); ``Fw``
    holds the object triangle's frame, ``Fc`` (3, 3) is scratch."""
    _triangle_frame(X[0], X[1], X[2], Fc)
    for i in range(3):
        for j in range(3):
            R[i, j] = Fc[i, 0] * Fw[j, 0] + Fc[i, 1] * Fw[j, 1] + Fc[i, 2] * Fw[j, 2]
    for i in range(3):
        t[i] = X[0, i] - (R[i, 0] * Pw[0, 0] + R[i, 1] * Pw[0, 1] + R[i, 2] * Pw[0, 2])


@njit(cache=True)
def _squared_distance(a, b):
    return (a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2


@njit(cache=True)
def p3p(Pw, bearings, Rs, ts):
    """Poses ``(Rs[k], ts[k])`` (object to camera) that put ``Pw`` (3, 3) mm on the unit rays
    ``bearings`` (3, 3); up to four, into ``Rs`` (4, 3, 3) and ``ts`` (4, 3). Returns how many
    (0 for a degenerate triangle)."""
    j1, j2, j3 = bearings[0], bearings[1], bearings[2]
    a2 = _squared_distance(Pw[1], Pw[2])
    b2 = _squared_distance(Pw[0], Pw[2])
    c2 = _squared_distance(Pw[0], Pw[1])
    if a2 < 1e-12 or b2 < 1e-12 or c2 < 1e-12:
        return 0
    ca = j2[0] * j3[0] + j2[1] * j3[1] + j2[2] * j3[2]
    cb = j1[0] * j3[0] + j1[1] * j3[1] + j1[2] * j3[2]
    cg = j1[0] * j2[0] + j1[1] * j2[1] + j1[2] * j2[2]
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
    if nv == 0:
        return 0
    scratch = np.empty((3, 3, 3))
    X, Fw, Fc = scratch[0], scratch[1], scratch[2]
    _triangle_frame(Pw[0], Pw[1], Pw[2], Fw)
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
        for i in range(3):
            X[0, i] = s1 * j1[i]
            X[1, i] = u * s1 * j2[i]
            X[2, i] = v * s1 * j3[i]
        _kabsch(Pw, X, Fw, Fc, Rs[count], ts[count])
        count += 1
    return count
