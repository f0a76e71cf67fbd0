"""The damped Newton (Levenberg-Marquardt) loop, compiled, for one problem or a batch.

Undamped, each step is the paper's Newton step (its equation 7 solved in the least-squares
sense). Damping starts negligible and grows only when a step fails to reduce the cost or
throws a point behind the camera, which is what makes convergence from far starts reliable.
With ``huber_px > 0`` the cost is Huber's loss on each point's residual length, minimised
by reweighting.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from calib_core.solver.kernels.camera_models import PINHOLE, evaluate
from calib_core.solver.kernels.small_linalg import cholesky_solve_in

# Outcome codes (see ``OUTCOMES``).
CONVERGED, EXACT_FIT, MAX_ITERATIONS, NO_DESCENT, DIVERGED, START_BEHIND, SINGULAR = range(7)
OUTCOMES = (
    "converged",
    "exact fit",
    "did not converge within the iteration limit",
    "found no step that reduces the reprojection error (a saddle or a bad start)",
    "diverged: a Newton step threw points behind the camera or the focal lengths out of range",
    "the starting pose puts points behind the camera",
    "the normal equations are singular (degenerate geometry)",
)

_LAMBDA_START = 1e-8
_LAMBDA_GIVE_UP = 1e10
_COST_RTOL = 1e-15
# A step predicted to lower the cost by this share of it or less is round-off: the pose it would move is a few
# millionths of its own standard deviation for 5000 pairs (the step's Mahalanobis length squared is about this times
# the pairs' count); at the minimum of 5000 pairs the round-off steps predict 1e-16 to 1e-15
_PREDICTED_RTOL = 1e-15
# ... judged only on a step this lightly damped (a heavily damped one is small because it is damped, not because the
# cost is at its minimum)
_UNDAMPED = 1e-6
# A step this small relative to the state ends the iterations: 1e-10 of the distance is
# 5e-8 mm at 500 mm, so one more Newton step would only polish round-off.
TRANSLATION_RTOL = 1e-10
ROTATION_TOL_RAD = 1e-11
FOCAL_RTOL = 1e-10
# Estimated focal lengths must stay within this factor range of their starting values.
FOCAL_RANGE = (0.2, 5.0)


@njit(cache=True)
def rotate_by(phi, R, out):
    """``out = R(phi) @ R`` with ``R(phi)`` the rotation of rotation vector ``phi`` (3,), rad."""
    theta = np.sqrt(phi[0] ** 2 + phi[1] ** 2 + phi[2] ** 2)
    if theta < 1e-12:
        s, c1 = 1.0, 0.5  # sin(theta)/theta and (1 - cos(theta))/theta^2 in the limit
    else:
        s, c1 = np.sin(theta) / theta, (1.0 - np.cos(theta)) / (theta * theta)
    x, y, z = phi[0], phi[1], phi[2]
    # (in scalars: an array made per step cost as much as the step's arithmetic for a few pairs)
    m00 = 1.0 - c1 * (y * y + z * z)
    m11 = 1.0 - c1 * (x * x + z * z)
    m22 = 1.0 - c1 * (x * x + y * y)
    m01 = -s * z + c1 * x * y
    m10 = s * z + c1 * x * y
    m02 = s * y + c1 * x * z
    m20 = -s * y + c1 * x * z
    m12 = -s * x + c1 * y * z
    m21 = s * x + c1 * y * z
    for j in range(3):
        r0, r1, r2 = R[0, j], R[1, j], R[2, j]
        out[0, j] = m00 * r0 + m01 * r1 + m02 * r2
        out[1, j] = m10 * r0 + m11 * r1 + m12 * r2
        out[2, j] = m20 * r0 + m21 * r1 + m22 * r2


@njit(cache=True)
def robust_cost(r, huber):
    """Sum of squared residual lengths, px^2, or Huber's loss when ``huber > 0``."""
    c = 0.0
    for i in range(r.shape[0]):
        e2 = r[i, 0] ** 2 + r[i, 1] ** 2
        if huber > 0.0 and e2 > huber * huber:
            c += 2.0 * huber * np.sqrt(e2) - huber * huber
        else:
            c += e2
    if not np.isfinite(c):
        return np.inf
    return c


@njit(cache=True)
def normal_equations(J, r, huber, p, A, g):
    """``A = J^T W J``, ``g = J^T W r`` with Huber weights W per point (1 without ``huber``)."""
    if p == 6 and huber <= 0.0:
        _pose_normal_equations(J, r, A, g)
        return
    A[:, :] = 0.0
    g[:] = 0.0
    for i in range(J.shape[0]):
        w = 1.0
        if huber > 0.0:
            e = np.sqrt(r[i, 0] ** 2 + r[i, 1] ** 2)
            if e > huber:
                w = huber / e
        for row in range(2):
            for a in range(p):
                ja = w * J[i, row, a]
                g[a] += ja * r[i, row]
                for b in range(a + 1):
                    A[a, b] += ja * J[i, row, b]
    for a in range(p):
        for b in range(a + 1, p):
            A[a, b] = A[b, a]


@njit(cache=True)
def _pose_normal_equations(J, r, A, g):
    """:func:`normal_equations` for the six pose unknowns without weights, its 21 sums in scalars: a sum kept in the
    array was loaded and stored for every pair (numba cannot tell ``A`` from ``J``), 100 us for 3500 pairs."""
    a00 = a10 = a11 = a20 = a21 = a22 = a30 = a31 = a32 = a33 = 0.0
    a40 = a41 = a42 = a43 = a44 = a50 = a51 = a52 = a53 = a54 = a55 = 0.0
    g0 = g1 = g2 = g3 = g4 = g5 = 0.0
    for i in range(J.shape[0]):
        for row in range(2):
            j0, j1, j2 = J[i, row, 0], J[i, row, 1], J[i, row, 2]
            j3, j4, j5 = J[i, row, 3], J[i, row, 4], J[i, row, 5]
            e = r[i, row]
            g0 += j0 * e
            g1 += j1 * e
            g2 += j2 * e
            g3 += j3 * e
            g4 += j4 * e
            g5 += j5 * e
            a00 += j0 * j0
            a10 += j1 * j0
            a11 += j1 * j1
            a20 += j2 * j0
            a21 += j2 * j1
            a22 += j2 * j2
            a30 += j3 * j0
            a31 += j3 * j1
            a32 += j3 * j2
            a33 += j3 * j3
            a40 += j4 * j0
            a41 += j4 * j1
            a42 += j4 * j2
            a43 += j4 * j3
            a44 += j4 * j4
            a50 += j5 * j0
            a51 += j5 * j1
            a52 += j5 * j2
            a53 += j5 * j3
            a54 += j5 * j4
            a55 += j5 * j5
    lower = (a00, a10, a11, a20, a21, a22, a30, a31, a32, a33, a40, a41, a42, a43, a44, a50, a51, a52, a53, a54, a55)
    k = 0
    for a in range(6):
        for b in range(a + 1):
            A[a, b] = lower[k]
            A[b, a] = lower[k]
            k += 1
    g[0], g[1], g[2], g[3], g[4], g[5] = g0, g1, g2, g3, g4, g5


@njit(cache=True)
def _step(R, t, f, delta, p, R_new, t_new, f_new):
    rotate_by(delta[3:6], R, R_new)
    for k in range(3):
        t_new[k] = t[k] + delta[k]
    f_new[0], f_new[1] = f[0], f[1]
    if p == 8:
        f_new[0] += delta[6]
        f_new[1] += delta[7]


@njit(cache=True)
def _small(delta, p, scale, f):
    if np.sqrt(delta[0] ** 2 + delta[1] ** 2 + delta[2] ** 2) > TRANSLATION_RTOL * scale:
        return False
    if np.sqrt(delta[3] ** 2 + delta[4] ** 2 + delta[5] ** 2) > ROTATION_TOL_RAD:
        return False
    if p == 8 and (abs(delta[6]) > FOCAL_RTOL * f[0] or abs(delta[7]) > FOCAL_RTOL * f[1]):
        return False
    return True


@njit(cache=True)
def _round_off_step(delta, g, p, cost):
    """Whether the step ``delta`` (p,) lowers the cost by no more than its round-off, as the quadratic model
    predicts (``delta . g``): at the minimum a step of noise raised the cost, and each smaller damped try cost an
    evaluation of every pair (a dozen for 3500 pairs) before the step shrank below :data:`TRANSLATION_RTOL`."""
    predicted = 0.0
    for a in range(p):
        predicted += delta[a] * g[a]
    return abs(predicted) <= _PREDICTED_RTOL * cost


@njit(cache=True)
def _focal_sane(f, f0):
    # A focal length running off to zero or infinity is the orthographic or degenerate limit, never a camera.
    return (
        FOCAL_RANGE[0] * f0[0] < f[0] < FOCAL_RANGE[1] * f0[0]
        and FOCAL_RANGE[0] * f0[1] < f[1] < FOCAL_RANGE[1] * f0[1]
    )


@njit(cache=True)
def newton_work(r, J, focal):
    """The room :func:`newton_in` works in, for residuals like ``r`` (n, 2) and a Jacobian like ``J`` (n, 2, p):
    made once by a loop that refines many seeds of one problem (made per call, it cost as much as the steps of four
    pairs)."""
    p = 8 if focal else 6
    return (
        np.empty_like(r),
        np.empty_like(J),
        np.empty((3, 3)),
        np.empty(3),
        np.empty(2),
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty(p),
        np.empty(p),
        np.empty(2),
    )


@njit(cache=True)
def newton(model, P, uv, R, t, f, cx, cy, dist, focal, as_printed, huber, max_iterations, damped, r, J):
    """Minimise the reprojection cost from the state ``(R, t, f)``, updated in place.

    ``R`` (3, 3), ``t`` (3,) (mm, or the paper's shifts), ``f`` (2,) = ``(fu, fv)`` px;
    ``r`` (n, 2) and ``J`` (n, 2, p) receive the residuals and Jacobian at the final
    state. Returns ``(iterations, outcome code)``.
    """
    work = newton_work(r, J, focal)
    return newton_in(model, P, uv, R, t, f, cx, cy, dist, focal, as_printed, huber, max_iterations, damped, r, J, work)


@njit(cache=True)
def newton_in(model, P, uv, R, t, f, cx, cy, dist, focal, as_printed, huber, max_iterations, damped, r, J, work):
    """:func:`newton` in the room ``work`` (:func:`newton_work`'s)."""
    n = P.shape[0]
    p = 8 if focal else 6
    zmin = evaluate(model, P, uv, R, t, f[0], f[1], cx, cy, dist, focal, as_printed, r, J)
    if not zmin > 0.0:
        return 0, START_BEHIND
    cost = robust_cost(r, huber)
    if model == PINHOLE:
        scale = max(np.sqrt(t[0] ** 2 + t[1] ** 2 + t[2] ** 2), 1.0)
    else:
        scale = max(abs(t[2]), 1.0)
    r_new, J_new, R_new, t_new, f_new, A, Aa, L, g, delta, f0 = work
    delta[:] = 0.0  # (a first factorisation that fails judges the step by it: none taken)
    f0[:] = f
    lam = _LAMBDA_START
    for iteration in range(1, max_iterations + 1):
        if cost <= 1e-28 * n:
            return iteration - 1, EXACT_FIT
        normal_equations(J, r, huber, p, A, g)
        if not damped:
            if not cholesky_solve_in(A, g, delta, L):
                return iteration, SINGULAR
            _step(R, t, f, delta, p, R_new, t_new, f_new)
            zmin = evaluate(model, P, uv, R_new, t_new, f_new[0], f_new[1], cx, cy, dist, focal, as_printed, r, J)
            R[:, :], t[:], f[:] = R_new, t_new, f_new
            cost = robust_cost(r, huber)
            if not (zmin > 0.0 and np.isfinite(cost) and _focal_sane(f, f0)):
                return iteration, DIVERGED
            if _small(delta, p, scale, f):
                return iteration, CONVERGED
            continue
        nu = 2.0
        while True:
            for a in range(p):
                for b in range(p):
                    Aa[a, b] = A[a, b]
                Aa[a, a] += lam * max(A[a, a], 1e-300)
            cost_new = np.inf
            if cholesky_solve_in(Aa, g, delta, L):
                if lam <= _UNDAMPED and _round_off_step(delta, g, p, cost):
                    return iteration - 1, CONVERGED
                _step(R, t, f, delta, p, R_new, t_new, f_new)
                zmin = evaluate(
                    model, P, uv, R_new, t_new, f_new[0], f_new[1], cx, cy, dist, focal, as_printed, r_new, J_new
                )
                if zmin > 0.0 and _focal_sane(f_new, f0):
                    cost_new = robust_cost(r_new, huber)
                if cost_new <= cost:
                    break
                if _small(delta, p, scale, f):
                    return iteration, CONVERGED
            lam *= nu
            nu *= 2.0
            if lam > _LAMBDA_GIVE_UP:
                return iteration, NO_DESCENT
        improvement = cost - cost_new
        R[:, :], t[:], f[:] = R_new, t_new, f_new
        r[:, :] = r_new
        J[:, :, :] = J_new
        cost = cost_new
        lam = max(lam / 3.0, 1e-15)
        if _small(delta, p, scale, f) or improvement <= _COST_RTOL * cost:
            return iteration, CONVERGED
    return max_iterations, MAX_ITERATIONS


@njit(cache=True, parallel=True)
def newton_batch(model, P, uv, R, t, f, cx, cy, dist, focal, max_iterations, r, J, iterations, outcomes):
    """:func:`newton` on each of ``b`` problems in parallel; arrays carry the batch index first."""
    for i in prange(P.shape[0]):
        it, code = newton(
            model, P[i], uv[i], R[i], t[i], f[i], cx, cy, dist, focal, False, 0.0, max_iterations, True, r[i], J[i]
        )
        iterations[i] = it
        outcomes[i] = code
