"""The whole solve in one compiled call: for many points a DLT seed, for a few P3P over the
largest triangles; Newton; the fit summary.

Most operator solves have six or more well-spread points; for them one call replaces a
dozen interpreter round trips (the solve then costs less than OpenCV's own refinement).
When the seed or the fit is not good enough the caller falls back to the full search.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from calib_core.solver.kernels.camera_models import PINHOLE
from calib_core.solver.kernels.diagnostics import fit_summary, flags_a_misfit
from calib_core.solver.kernels.dlt import dlt_pose
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT, MAX_ITERATIONS, newton, newton_in, newton_work
from calib_core.solver.kernels.p3p import p3p

# Fixed-point undistortion sweeps for the seed: the Newton iterations absorb what is left.
_SEED_UNDISTORT_SWEEPS = 8


@njit(cache=True)
def seed_coordinates(uv, fu, fv, cx, cy, dist):
    """Approximately undistorted normalized coordinates (n, 2) of pixels (n, 2), for seeding."""
    k1, k2, p1, p2, k3 = dist[0], dist[1], dist[2], dist[3], dist[4]
    n = uv.shape[0]
    xy = np.empty((n, 2))
    for i in range(n):
        xd = (uv[i, 0] - cx) / fu
        yd = (uv[i, 1] - cy) / fv
        x, y = xd, yd
        for _ in range(_SEED_UNDISTORT_SWEEPS):
            r2 = x * x + y * y
            radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
            x = (xd - (2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x))) / radial
            y = (yd - (p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y)) / radial
        xy[i, 0] = x
        xy[i, 1] = y
    return xy


@njit(cache=True)
def dlt_newton_summary(P, uv, fu, fv, cx, cy, dist, max_iterations, sigma_given, default_sigma, misfit_test):
    """Seed by DLT, refine, summarise. Returns ``None`` without a DLT seed, else :func:`_summary`'s tuple and no rival
    (empty rival arrays, as :func:`p3p_newton_summary` returns them; all arrays allocated here: one call,
    few interpreter round trips)."""
    n = P.shape[0]
    R = np.empty((3, 3))
    t = np.empty(3)
    if not dlt_pose(P, seed_coordinates(uv, fu, fv, cx, cy, dist), R, t):
        return None
    r = np.empty((n, 2))
    J = np.empty((n, 2, 6))
    f = np.array([fu, fv])
    iterations, outcome = newton(PINHOLE, P, uv, R, t, f, cx, cy, dist, False, False, 0.0, max_iterations, True, r, J)
    obj2cam, r, cov, cov_centre, loo, scalars = _summary(
        R, t, r, J, iterations, outcome, sigma_given, default_sigma, misfit_test
    )
    return (
        obj2cam,
        r,
        cov,
        cov_centre,
        loo,
        scalars,
        np.empty((0, 4, 4)),
        np.empty((0, 2), dtype=np.int64),
        np.empty((0, n, 2)),
        np.empty((0, n, 2, 6)),
    )


@njit(cache=True)
def _summary(R, t, r, J, iterations, outcome, sigma_given, default_sigma, misfit_test):
    """What the fast path returns for a fit: ``(obj2cam (4, 4), residuals (n, 2), covariance (6, 6), centre
    covariance (3, 3), leave-one-out (n,), scalars)`` with ``scalars`` = ``iterations, outcome, rms px, sigma px,
    sigma source, condition, misfit`` (misfit: :func:`flags_a_misfit`'s answer, ``misfit_test`` = ``(noise px, fisher
    limit, own-scale minimum dof, false flags per solve)``; 0 for an exact fit, where no pair can be flagged)."""
    n = r.shape[0]
    cov = np.empty((6, 6))
    cov_centre = np.empty((3, 3))
    loo = np.empty(n)
    lengths = np.empty(n)
    rms, sigma, source, condition = fit_summary(
        J, r, np.ones(n), R, t, sigma_given, default_sigma, cov, cov_centre, loo, lengths
    )
    misfit = 0
    if sigma > 0.0:
        cov_unit = cov / (sigma * sigma)
        noise, fisher_limit, own_scale_min_dof, false_flags = misfit_test
        misfit = flags_a_misfit(J, r, cov_unit, noise, fisher_limit, own_scale_min_dof, false_flags)
    obj2cam = np.zeros((4, 4))
    obj2cam[:3, :3] = R
    obj2cam[:3, 3] = t
    obj2cam[3, 3] = 1.0
    scalars = np.array([iterations, outcome, rms, sigma, source, condition, misfit], dtype=np.float64)
    return obj2cam, r, cov, cov_centre, loo, scalars


@njit(cache=True)
def _same_pose(Ra, ta, Rb, tb, cos_limit, rel_translation):
    # (element by element: it runs for every pair of seeds, where an array made per call costs more than the test)
    scale = max(np.sqrt(ta[0] ** 2 + ta[1] ** 2 + ta[2] ** 2), 1.0)
    gap = np.sqrt((ta[0] - tb[0]) ** 2 + (ta[1] - tb[1]) ** 2 + (ta[2] - tb[2]) ** 2)
    if gap > rel_translation * scale:
        return False
    trace = 0.0
    for i in range(3):
        for j in range(3):
            trace += Ra[i, j] * Rb[i, j]
    return (trace - 1.0) / 2.0 >= cos_limit


_FIRST_STEPS = 3
"""A seed after the first is refined this many steps, then checked against the minima found, before the rest."""


@njit(cache=True)
def _near_a_minimum(Rs, ts, costs, R, t, basin_cos):
    """Whether ``(R, t)`` is within the basin (``basin_cos``, 5 % of the distance) of a minimum found (finite cost)."""
    for i in range(costs.shape[0]):
        if costs[i] < np.inf and _same_pose(Rs[i], ts[i], R, t, basin_cos, 0.05):
            return True
    return False


@njit(cache=True)
def largest_triangles(P, limit):
    """Up to ``limit`` triplets of the points ``P`` (n, 3), (k, 3) indices, the largest triangles first (the best
    conditioned P3P; ties in the order of enumeration); all of them, in that order, when there are no more."""
    n = P.shape[0]
    count = n * (n - 1) * (n - 2) // 6
    every = np.empty((count, 3), dtype=np.int64)
    k = 0
    for a in range(n):
        for b in range(a + 1, n):
            for c in range(b + 1, n):
                every[k, 0], every[k, 1], every[k, 2] = a, b, c
                k += 1
    if count <= limit:
        return every
    area = np.empty(count)
    for k in range(count):
        a, b, c = every[k, 0], every[k, 1], every[k, 2]
        u0, u1, u2 = P[b, 0] - P[a, 0], P[b, 1] - P[a, 1], P[b, 2] - P[a, 2]
        v0, v1, v2 = P[c, 0] - P[a, 0], P[c, 1] - P[a, 1], P[c, 2] - P[a, 2]
        w0, w1, w2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        area[k] = -np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    return every[np.argsort(area, kind="mergesort")[:limit]]


@njit(cache=True)
def p3p_newton_summary(
    P,
    uv,
    fu,
    fv,
    cx,
    cy,
    dist,
    max_iterations,
    sigma_given,
    default_sigma,
    misfit_test,
    gate_px,
    margin_cost,
    same_cos,
    same_rel,
    max_triplets,
):
    """The whole solve for a few points (four to eight): P3P over the ``max_triplets`` largest triangles (the full
    search's triplets, :func:`calib_core.solver.initialisation.spread_triplets`), the roots that put all the points
    within ``gate_px`` (RMS) refined, summarised as :func:`dlt_newton_summary`, with the **rivals** (k, 4, 4): every
    other distinct minimum (``same_cos``/``same_rel``: the cosine and relative distance under which two poses are one)
    costing within ``margin_cost`` px^2 of the best (a plane's mirror pose), best first, and their fits (k, 2): each
    one's Newton iterations and outcome; empty when the best stands alone; then the residuals (k + 1, n, 2) and
    Jacobians (k + 1, n, 2, 6) at the best's minimum and each rival's. ``None`` when no root is near or no
    refinement converges."""
    n = P.shape[0]
    xy = seed_coordinates(uv, fu, fv, cx, cy, dist)
    bearings = np.empty((n, 3))
    for i in range(n):
        norm = np.sqrt(xy[i, 0] ** 2 + xy[i, 1] ** 2 + 1.0)
        bearings[i, 0] = xy[i, 0] / norm
        bearings[i, 1] = xy[i, 1] / norm
        bearings[i, 2] = 1.0 / norm
    triplets = largest_triangles(P, max_triplets)
    m_max = 4 * triplets.shape[0]
    Rs = np.empty((m_max, 3, 3))
    ts = np.empty((m_max, 3))
    seed_rms = np.empty(m_max)
    m = 0
    Rk = np.empty((4, 3, 3))
    tk = np.empty((4, 3))
    tri_P = np.empty((3, 3))
    tri_b = np.empty((3, 3))
    seed_cos = np.cos(np.radians(2.0))
    for tri in range(triplets.shape[0]):
        for v in range(3):
            tri_P[v] = P[triplets[tri, v]]
            tri_b[v] = bearings[triplets[tri, v]]
        for k in range(p3p(tri_P, tri_b, Rk, tk)):
            # all the points within the gate, in front of the camera
            e2 = 0.0
            front = True
            R_, t_ = Rk[k], tk[k]
            for i in range(n):
                x = R_[0, 0] * P[i, 0] + R_[0, 1] * P[i, 1] + R_[0, 2] * P[i, 2] + t_[0]
                y = R_[1, 0] * P[i, 0] + R_[1, 1] * P[i, 1] + R_[1, 2] * P[i, 2] + t_[1]
                z = R_[2, 0] * P[i, 0] + R_[2, 1] * P[i, 1] + R_[2, 2] * P[i, 2] + t_[2]
                if z <= 0.0:
                    front = False
                    break
                e2 += ((x / z - xy[i, 0]) * fu) ** 2 + ((y / z - xy[i, 1]) * fv) ** 2
            if not front or not np.sqrt(e2 / n) <= gate_px:
                continue
            copy = False
            for j in range(m):
                if _same_pose(Rs[j], ts[j], Rk[k], tk[k], seed_cos, 0.02):
                    copy = True
                    break
            if not copy:
                Rs[m] = Rk[k]
                ts[m] = tk[k]
                seed_rms[m] = np.sqrt(e2 / n)
                m += 1
    if m == 0:
        return None
    order = np.argsort(seed_rms[:m])
    rs = np.empty((m, n, 2))
    Js = np.empty((m, n, 2, 6))
    costs = np.full(m, np.inf)
    its = np.zeros(m, dtype=np.int64)
    outcomes = np.zeros(m, dtype=np.int64)
    f = np.empty(2)
    best = -1
    basin_cos = np.cos(np.radians(5.0))
    work = newton_work(rs[0], Js[0], False)
    for j in order:
        # best seeds first; one within a few degrees of a pose already found would only find it again
        # (the true pose's roots from each triplet, apart by the noise)
        if _near_a_minimum(Rs, ts, costs, Rs[j], ts[j], basin_cos):
            continue
        f[0], f[1] = fu, fv
        # the first seed to its minimum at once; each later one a few steps at a time, leaving it as soon as it comes
        # within the basin of a minimum found (on a plane the triplets' roots of one pose lie far apart, its turn
        # poorly fixed by three points, and each takes a dozen steps down the valley to the minimum found already)
        chunk = max_iterations if best < 0 else min(_FIRST_STEPS, max_iterations)
        its[j], outcomes[j] = 0, MAX_ITERATIONS
        joined = False
        while outcomes[j] == MAX_ITERATIONS and its[j] < max_iterations:
            if its[j] > 0 and _near_a_minimum(Rs, ts, costs, Rs[j], ts[j], basin_cos):
                joined = True
                break
            steps = min(chunk, max_iterations - its[j])
            more, outcomes[j] = newton_in(
                PINHOLE, P, uv, Rs[j], ts[j], f, cx, cy, dist, False, False, 0.0, steps, True, rs[j], Js[j], work
            )
            its[j] += more
        if joined:
            continue
        if outcomes[j] == CONVERGED or outcomes[j] == EXACT_FIT:
            costs[j] = np.sum(rs[j] ** 2)
            if best < 0 or costs[j] < costs[best]:
                best = j
    if best < 0:
        return None
    rivals = np.zeros((m, 4, 4))
    rival_fits = np.zeros((m, 2), dtype=np.int64)
    # the best's and each rival's residuals and Jacobian at their minima, best first (a tie's minima are handed on
    # as refined: evaluating them again cost a quarter of a tied solve)
    minima_r = np.empty((m, n, 2))
    minima_J = np.empty((m, n, 2, 6))
    minima_r[0] = rs[best]
    minima_J[0] = Js[best]
    k = 0
    for j in np.argsort(costs):
        if (
            j != best
            and costs[j] <= costs[best] + margin_cost
            and not _same_pose(Rs[best], ts[best], Rs[j], ts[j], same_cos, same_rel)
        ):
            rivals[k, :3, :3] = Rs[j]
            rivals[k, :3, 3] = ts[j]
            rivals[k, 3, 3] = 1.0
            rival_fits[k, 0], rival_fits[k, 1] = its[j], outcomes[j]
            minima_r[k + 1] = rs[j]
            minima_J[k + 1] = Js[j]
            k += 1
    obj2cam, r, cov, cov_centre, loo, scalars = _summary(
        Rs[best],
        ts[best],
        rs[best].copy(),
        Js[best],
        its[best],
        outcomes[best],
        sigma_given,
        default_sigma,
        misfit_test,
    )
    return (
        obj2cam,
        r,
        cov,
        cov_centre,
        loo,
        scalars,
        rivals[:k].copy(),
        rival_fits[:k].copy(),
        minima_r[: k + 1].copy(),
        minima_J[: k + 1].copy(),
    )
