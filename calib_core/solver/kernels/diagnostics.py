"""Compiled covariance, conditioning and leave-one-out residuals at a solved pose."""

from __future__ import annotations

import numpy as np
from numba import njit

from calib_core.solver.kernels.small_linalg import spd_inverse, symmetric_eigenvalues


@njit(cache=True)
def hat_block(J, i, cov_unit):
    """``(h00, h01, h11)``: pair ``i``'s 2 x 2 block of the hat matrix ``J_i cov_unit J_i^T`` (symmetric), from the
    Jacobian ``J`` (n, 2, p) and ``cov_unit`` (p, p) = ``(J^T W J)^-1``."""
    p = J.shape[2]
    h00 = 0.0
    h01 = 0.0
    h11 = 0.0
    for a in range(p):
        for b in range(p):
            c = cov_unit[a, b]
            h00 += J[i, 0, a] * c * J[i, 0, b]
            h01 += J[i, 0, a] * c * J[i, 1, b]
            h11 += J[i, 1, a] * c * J[i, 1, b]
    return h00, h01, h11


@njit(cache=True)
def information_diagnostics(J, r, w, R, t, cov_unit, cov_centre_unit, loo):
    """Fill ``cov_unit`` (p, p) with ``(J^T W J)^-1`` (the covariance for unit pixel noise),
    ``cov_centre_unit`` (3, 3) with the covariance of the camera centre ``c = -R^T t`` in the
    object frame, and ``loo`` (n,) with first-order leave-one-out residual lengths, px;
    return the condition number of the column-scaled Jacobian (inf when singular).

    ``J`` (n, 2, p) Jacobian of the predicted pixels, ``r`` (n, 2) residuals, ``w`` (n,)
    point weights (0 drops a point). Leave-one-out uses the 2x2 blocks of the hat matrix,
    ``(I - H_ii)^-1 r_i``: no re-solve; NaN where dropping the point leaves no redundancy.
    """
    n, _, p = J.shape
    A = np.zeros((p, p))
    for i in range(n):
        for row in range(2):
            for a in range(p):
                ja = w[i] * J[i, row, a]
                for b in range(p):
                    A[a, b] += ja * J[i, row, b]
    s = np.empty(p)
    for a in range(p):
        s[a] = np.sqrt(A[a, a]) if A[a, a] > 0.0 else 1.0
    As = np.empty((p, p))
    for a in range(p):
        for b in range(p):
            As[a, b] = A[a, b] / (s[a] * s[b])
    eig = symmetric_eigenvalues(As)
    inv_s = np.empty((p, p))
    if not eig[0] > 1e-14 * eig[-1] or not spd_inverse(As, inv_s):
        cov_unit[:, :] = np.inf
        cov_centre_unit[:, :] = np.inf
        loo[:] = np.nan
        return np.inf
    for a in range(p):
        for b in range(p):
            cov_unit[a, b] = inv_s[a, b] / (s[a] * s[b])
    # dc/dt = -R^T, dc/dphi = -R^T [t]x (rotations pre-multiplied about the camera axes).
    tx = np.zeros((3, 3))
    tx[0, 1], tx[0, 2], tx[1, 2] = -t[2], t[1], -t[0]
    tx[1, 0], tx[2, 0], tx[2, 1] = t[2], -t[1], t[0]
    Ac = np.zeros((3, 6))
    for a in range(3):
        for b in range(3):
            Ac[a, b] = -R[b, a]
            for k in range(3):
                Ac[a, 3 + b] -= R[k, a] * tx[k, b]
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for k in range(6):
                for m in range(6):
                    acc += Ac[a, k] * cov_unit[k, m] * Ac[b, m]
            cov_centre_unit[a, b] = acc
    for i in range(n):
        h00, h01, h11 = hat_block(J, i, cov_unit)
        m00 = 1.0 - w[i] * h00
        m01 = -w[i] * h01
        m11 = 1.0 - w[i] * h11
        det = m00 * m11 - m01 * m01
        if abs(det) <= 1e-9:
            loo[i] = np.nan
        else:
            d0 = (m11 * r[i, 0] - m01 * r[i, 1]) / det
            d1 = (-m01 * r[i, 0] + m00 * r[i, 1]) / det
            loo[i] = np.sqrt(d0 * d0 + d1 * d1)
    return np.sqrt(eig[-1] / eig[0])


@njit(cache=True)
def fit_summary(J, r, w, R, t, sigma_given, default_sigma, cov, cov_centre, loo, lengths):
    """Everything a solution reports about its fit, in one pass.

    Fills ``lengths`` (n,) with the residual lengths, px, and ``cov``/``cov_centre``/``loo``
    as :func:`information_diagnostics`, scaled by the noise used: ``sigma_given`` when it
    is positive, else estimated from the weighted residuals when there is redundancy, else
    ``default_sigma``. Returns ``(rms over weighted points px, sigma px, source, condition)``
    with source 0 given, 1 estimated, 2 default.
    """
    n, _, p = J.shape
    cost = 0.0
    used = 0
    for i in range(n):
        lengths[i] = np.sqrt(r[i, 0] ** 2 + r[i, 1] ** 2)
        if w[i] > 0.0:
            cost += lengths[i] ** 2
            used += 1
    rms = np.sqrt(cost / used) if used else np.nan
    redundancy = 2 * used - p
    if sigma_given > 0.0:
        sigma, source = sigma_given, 0
    elif redundancy > 0:
        sigma, source = np.sqrt(cost / redundancy), 1
    else:
        sigma, source = default_sigma, 2
    condition = information_diagnostics(J, r, w, R, t, cov, cov_centre, loo)
    s2 = sigma * sigma
    for a in range(p):
        for b in range(p):
            cov[a, b] *= s2
    for a in range(3):
        for b in range(3):
            cov_centre[a, b] *= s2
    return rms, sigma, source, condition


@njit(cache=True)
def flags_a_misfit(J, r, cov_unit, noise, fisher_limit, own_scale_min_dof, false_flag_per_solve):
    """Whether :func:`calib_core.solver.misfit.flag_misfits` would flag a pair of this fit (every pair used), compiled
    for the fast path: ``T_i = r_i^T (I - H_ii)^-1 r_i`` from the hat matrix's 2 x 2 blocks (``cov_unit`` (p, p) =
    ``(J^T J)^-1``), each against the noise or the other pairs' own scale. ``fisher_limit``: ``2 F(2, dof)`` at the
    false-flag quantile for ``n`` pairs. Returns 1 (a pair flagged), 0 (none), -1 (a pair the fit cannot judge: the
    full test decides)."""
    n, _, p = J.shape
    dof = 2 * n - p - 2
    if n < 3 or dof <= 0:
        return 0
    T = np.empty(n)
    rss = 0.0
    for i in range(n):
        h00, h01, h11 = hat_block(J, i, cov_unit)
        m00 = 1.0 - h00
        m11 = 1.0 - h11
        det = m00 * m11 - h01 * h01
        if not det > 1e-9:
            return -1
        T[i] = (m11 * r[i, 0] * r[i, 0] + 2.0 * h01 * r[i, 0] * r[i, 1] + m00 * r[i, 1] * r[i, 1]) / det
        rss += r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1]
    chi2_limit = -2.0 * np.log(false_flag_per_solve / n)
    for i in range(n):
        others = max(rss - T[i], 0.0) / dof if dof >= own_scale_min_dof else 0.0
        scale = np.sqrt(others)
        sigma = max(noise, scale)
        limit = fisher_limit if scale > noise else chi2_limit
        if T[i] / (sigma * sigma) > limit:
            return 1
    return 0


@njit(cache=True)
def quadratic_forms(J, r, used, rows, sign, out):
    """Fill ``out`` (len(rows),) with ``r_i^T (I + sign H_ii)^-1 r_i`` px^2 for the pairs ``rows`` (k,) int, ``H_ii``
    the 2 x 2 hat block of the least-squares fit over the ``used`` (n,) bool pairs (``J`` (n, 2, p), ``r`` (n, 2)
    px); NaN where the block is singular, or every row when the fit has no redundancy or a singular information
    matrix."""
    n, _, p = J.shape
    out[:] = np.nan
    count = 0
    A = np.zeros((p, p))
    for i in range(n):
        if not used[i]:
            continue
        count += 1
        for row in range(2):
            for a in range(p):
                ja = J[i, row, a]
                for b in range(a + 1):
                    A[a, b] += ja * J[i, row, b]
    if 2 * count <= p:
        return
    for a in range(p):
        for b in range(a + 1, p):
            A[a, b] = A[b, a]
    cov_unit = np.empty((p, p))
    if not spd_inverse(A, cov_unit):
        return
    for k in range(rows.shape[0]):
        i = rows[k]
        h00, h01, h11 = hat_block(J, i, cov_unit)
        m00 = 1.0 + sign * h00
        m01 = sign * h01
        m11 = 1.0 + sign * h11
        det = m00 * m11 - m01 * m01
        if det > 1e-9:
            out[k] = (m11 * r[i, 0] * r[i, 0] - 2.0 * m01 * r[i, 0] * r[i, 1] + m00 * r[i, 1] * r[i, 1]) / det


@njit(cache=True)
def misfit_flags(statistics, residuals, used, dof, noise, chi2_limit, fisher_limit, own_scale_min_dof, flags, sigma):
    """:func:`calib_core.solver.misfit.flag_misfits`'s arithmetic: fill ``flags`` (n,) bool and ``sigma`` (n,) px.
    ``statistics`` (n,) px^2 (NaN where a pair is not judged), ``residuals`` (n, 2) px, ``used`` (n,) bool, ``dof``
    the fit's degrees of freedom without one pair; a pair's sigma is the larger of ``noise`` and the other pairs' own
    scale (measured with ``dof >= own_scale_min_dof``), its limit ``fisher_limit`` where that scale rules, else
    ``chi2_limit``."""
    n = statistics.shape[0]
    rss = 0.0
    for i in range(n):
        if used[i]:
            rss += residuals[i, 0] * residuals[i, 0] + residuals[i, 1] * residuals[i, 1]
    for i in range(n):
        s = statistics[i]
        finite = np.isfinite(s)
        others = max(rss - s, 0.0) / dof if finite and dof >= own_scale_min_dof else 0.0
        scale = np.sqrt(others)
        sigma[i] = max(noise, scale)
        limit = fisher_limit if scale > noise else chi2_limit
        flags[i] = not np.isnan(s) and s / (sigma[i] * sigma[i]) > limit
