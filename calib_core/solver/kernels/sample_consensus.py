"""The robust sampler's hypotheses, compiled: P3P on random triplets, each pose scored by MSAC over every pair.

The pose only seeds the consensus (:func:`calib_core.solver.consensus.consensus_refine`), which fits every pair it
agrees with, round after round, as LO-RANSAC's local optimisation does: the sampler itself needs none. PoseLib's
LO-MSAC did the same work with its own local optimisation and bundle adjustment, and through its binding: 85 us for
20 pairs (40 hypotheses at 0.9999), 0.9 ms for 300.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from calib_core.solver.kernels.p3p import p3p


@njit(cache=True)
def _needed(inliers, n, confidence, sample):
    """Hypotheses enough to have drawn an all-inlier sample of ``sample`` pairs with ``confidence``, at the inlier
    share ``inliers / n``."""
    w = inliers / n
    p_good = w**sample
    if p_good >= 1.0:
        return 0
    if p_good <= 0.0:
        return 1 << 30
    return int(np.ceil(np.log(1.0 - confidence) / np.log(1.0 - p_good)))


@njit(cache=True)
def sample_consensus(P, uv, fu, fv, cx, cy, threshold_px, confidence, min_hypotheses, max_hypotheses, seed, R, t, inl):
    """The best pose (MSAC: each pair's squared error capped at ``threshold_px`` squared, a pair behind the camera at
    the cap) of P3P on random triplets of the pairs ``P`` (n, 3) mm, ``uv`` (n, 2) px (pinhole, without distortion),
    into ``R`` (3, 3) and ``t`` (3,) mm, its pairs within ``threshold_px`` into ``inl`` (n,) bool; drawing until an
    all-inlier triplet has been drawn with ``confidence`` at the best pose's inlier share (at least
    ``min_hypotheses`` draws, at most ``max_hypotheses``), from a generator seeded by ``seed``. Returns the best pose's
    inlier count (0 when no triplet gave a pose)."""
    n = P.shape[0]
    bearings = np.empty((n, 3))
    for i in range(n):
        x = (uv[i, 0] - cx) / fu
        y = (uv[i, 1] - cy) / fv
        norm = np.sqrt(x * x + y * y + 1.0)
        bearings[i, 0], bearings[i, 1], bearings[i, 2] = x / norm, y / norm, 1.0 / norm
    np.random.seed(seed)
    cap = threshold_px * threshold_px
    tri_P = np.empty((3, 3))
    tri_b = np.empty((3, 3))
    Rs = np.empty((4, 3, 3))
    ts = np.empty((4, 3))
    best_score = np.inf
    best_count = 0
    needed = max_hypotheses
    drawn = 0
    while drawn < max(min_hypotheses, min(needed, max_hypotheses)):
        drawn += 1
        a = np.random.randint(n)
        b = np.random.randint(n - 1)
        b += b >= a
        c = np.random.randint(n - 2)
        lo, hi = min(a, b), max(a, b)
        c += c >= lo
        c += c >= hi
        for k, idx in enumerate((a, b, c)):
            for j in range(3):
                tri_P[k, j] = P[idx, j]
                tri_b[k, j] = bearings[idx, j]
        for s in range(p3p(tri_P, tri_b, Rs, ts)):
            score = 0.0
            count = 0
            for i in range(n):
                X0 = Rs[s, 0, 0] * P[i, 0] + Rs[s, 0, 1] * P[i, 1] + Rs[s, 0, 2] * P[i, 2] + ts[s, 0]
                X1 = Rs[s, 1, 0] * P[i, 0] + Rs[s, 1, 1] * P[i, 1] + Rs[s, 1, 2] * P[i, 2] + ts[s, 1]
                X2 = Rs[s, 2, 0] * P[i, 0] + Rs[s, 2, 1] * P[i, 1] + Rs[s, 2, 2] * P[i, 2] + ts[s, 2]
                if X2 <= 0.0:
                    score += cap
                    continue
                du = fu * X0 / X2 + cx - uv[i, 0]
                dv = fv * X1 / X2 + cy - uv[i, 1]
                e2 = du * du + dv * dv
                if e2 < cap:
                    score += e2
                    count += 1
                else:
                    score += cap
                if score >= best_score:
                    break
            if score < best_score:
                best_score = score
                best_count = count
                R[:, :] = Rs[s]
                t[:] = ts[s]
                needed = _needed(best_count, n, confidence, 3)
    if best_count == 0:
        return 0
    count = 0
    for i in range(n):
        X0 = R[0, 0] * P[i, 0] + R[0, 1] * P[i, 1] + R[0, 2] * P[i, 2] + t[0]
        X1 = R[1, 0] * P[i, 0] + R[1, 1] * P[i, 1] + R[1, 2] * P[i, 2] + t[1]
        X2 = R[2, 0] * P[i, 0] + R[2, 1] * P[i, 1] + R[2, 2] * P[i, 2] + t[2]
        inside = False
        if X2 > 0.0:
            du = fu * X0 / X2 + cx - uv[i, 0]
            dv = fv * X1 / X2 + cy - uv[i, 1]
            inside = du * du + dv * dv < cap
        inl[i] = inside
        count += inside
    return count
