"""Reprojection residuals and analytic Jacobians of the two camera models, one point at a time.

Pose parameters follow Lowe's update, as in the paper: a step ``(dt, phi)`` moves the
pose ``(R, t)`` to ``(R(phi) R, t + dt)``; ``phi`` (rad) is an incremental rotation
about the *camera* axes, pre-multiplied. Jacobian columns: ``dt_x, dt_y, dt_z, phi_x,
phi_y, phi_z`` and, when the focal lengths are unknowns, ``fu, fv``. Residuals are
``observed - predicted``, px; the Jacobian is that of the *predicted* pixels.

Pinhole: ``(u, v) = (fu x_d + cx, fv y_d + cy)`` with ``(x_d, y_d)`` OpenCV's lens model
applied to ``(X/Z, Y/Z)``, ``(X, Y, Z) = R p + t`` (t in mm).

Paper (its equations 1-6): ``u = fu p'_x / (p'_z + d_z) + d_x``, ``v = fv p'_y / (p'_z +
d_z) + d_y`` with ``p' = R p``; ``t`` holds ``(d_x px, d_y px, d_z mm)``. The derivatives
are the paper's with its two misprints fixed (``c = 1 / (p'_z + d_z)``, ``dv/dd_z = -fv
c^2 p'_y``); ``as_printed`` uses the table exactly as printed.
"""

from __future__ import annotations

import numpy as np
from numba import njit

PINHOLE = 0
PAPER = 1


@njit(cache=True)
def pinhole_eval(P, uv, R, t, fu, fv, cx, cy, dist, focal, r, J):
    """Fill ``r`` (n, 2) and ``J`` (n, 2, p) for the pinhole model; return the smallest depth Z, mm."""
    k1, k2, p1, p2, k3 = dist[0], dist[1], dist[2], dist[3], dist[4]
    zmin = np.inf
    # (the perspective division's derivatives in scalars, not two arrays made per call: a Newton step of four pairs
    # cost as much in allocations as in arithmetic)
    for i in range(P.shape[0]):
        qx = R[0, 0] * P[i, 0] + R[0, 1] * P[i, 1] + R[0, 2] * P[i, 2]
        qy = R[1, 0] * P[i, 0] + R[1, 1] * P[i, 1] + R[1, 2] * P[i, 2]
        qz = R[2, 0] * P[i, 0] + R[2, 1] * P[i, 1] + R[2, 2] * P[i, 2]
        Z = qz + t[2]
        zmin = min(zmin, Z)
        iz = 1.0 / Z
        x = (qx + t[0]) * iz
        y = (qy + t[1]) * iz
        r2 = x * x + y * y
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        drad = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)
        xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x)
        yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y
        r[i, 0] = uv[i, 0] - (fu * xd + cx)
        r[i, 1] = uv[i, 1] - (fv * yd + cy)
        d00 = radial + 2.0 * x * x * drad + 2.0 * p1 * y + 6.0 * p2 * x
        d01 = 2.0 * x * y * drad + 2.0 * p1 * x + 2.0 * p2 * y
        d11 = radial + 2.0 * y * y * drad + 6.0 * p1 * y + 2.0 * p2 * x
        # d(x, y)/d(dt, phi): dp/dt = I, dp/dphi = -[q]x, then the perspective division.
        a0, a1, a2 = iz, 0.0, -x * iz
        a3, a4, a5 = -x * qy * iz, (qz + x * qx) * iz, -qy * iz
        b0, b1, b2 = 0.0, iz, -y * iz
        b3, b4, b5 = -(qz + y * qy) * iz, y * qx * iz, qx * iz
        J[i, 0, 0], J[i, 1, 0] = fu * (d00 * a0 + d01 * b0), fv * (d01 * a0 + d11 * b0)
        J[i, 0, 1], J[i, 1, 1] = fu * (d00 * a1 + d01 * b1), fv * (d01 * a1 + d11 * b1)
        J[i, 0, 2], J[i, 1, 2] = fu * (d00 * a2 + d01 * b2), fv * (d01 * a2 + d11 * b2)
        J[i, 0, 3], J[i, 1, 3] = fu * (d00 * a3 + d01 * b3), fv * (d01 * a3 + d11 * b3)
        J[i, 0, 4], J[i, 1, 4] = fu * (d00 * a4 + d01 * b4), fv * (d01 * a4 + d11 * b4)
        J[i, 0, 5], J[i, 1, 5] = fu * (d00 * a5 + d01 * b5), fv * (d01 * a5 + d11 * b5)
        if focal:
            J[i, 0, 6] = xd
            J[i, 0, 7] = 0.0
            J[i, 1, 6] = 0.0
            J[i, 1, 7] = yd
    return zmin


@njit(cache=True)
def paper_eval(P, uv, R, d, fu, fv, focal, as_printed, r, J):
    """Fill ``r`` (n, 2) and ``J`` (n, 2, p) for the paper's model; return the smallest ``p'_z + d_z``, mm."""
    zmin = np.inf
    for i in range(P.shape[0]):
        px = R[0, 0] * P[i, 0] + R[0, 1] * P[i, 1] + R[0, 2] * P[i, 2]
        py = R[1, 0] * P[i, 0] + R[1, 1] * P[i, 1] + R[1, 2] * P[i, 2]
        pz = R[2, 0] * P[i, 0] + R[2, 1] * P[i, 1] + R[2, 2] * P[i, 2]
        depth = pz + d[2]
        zmin = min(zmin, depth)
        c = 1.0 / depth
        r[i, 0] = uv[i, 0] - (fu * px * c + d[0])
        r[i, 1] = uv[i, 1] - (fv * py * c + d[1])
        cj = 1.0 / (px * px + d[2]) if as_printed else c
        J[i, 0, 0] = 1.0
        J[i, 0, 1] = 0.0
        J[i, 0, 2] = -fu * cj * cj * px
        J[i, 0, 3] = -fu * cj * cj * px * py
        J[i, 0, 4] = fu * cj * (pz + cj * px * px)
        J[i, 0, 5] = -fu * cj * py
        J[i, 1, 0] = 0.0
        J[i, 1, 1] = 1.0
        J[i, 1, 2] = -fv * cj * cj * (px if as_printed else py)
        J[i, 1, 3] = -fv * cj * (pz + cj * py * py)
        J[i, 1, 4] = fv * cj * cj * px * py
        J[i, 1, 5] = fv * cj * px
        if focal:
            J[i, 0, 6] = px * c
            J[i, 0, 7] = 0.0
            J[i, 1, 6] = 0.0
            J[i, 1, 7] = py * c
    return zmin


@njit(cache=True)
def evaluate(model, P, uv, R, t, fu, fv, cx, cy, dist, focal, as_printed, r, J):
    """Dispatch to the model; returns the smallest depth, mm (<= 0: a point is behind the camera)."""
    if model == PINHOLE:
        return pinhole_eval(P, uv, R, t, fu, fv, cx, cy, dist, focal, r, J)
    return paper_eval(P, uv, R, t, fu, fv, focal, as_printed, r, J)
