"""The robust mode's sampler: MSAC on P3P over random triplets with an adaptive stop at the requested confidence,
compiled (:mod:`calib_core.solver.kernels.sample_consensus`); when the pairs come ordered by confidence, PoseLib's
LO-MSAC with PROSAC's progressive sampling. It gives one seed and its inliers for the consensus refinement.

The inlier threshold follows the pick noise, not a fixed number of pixels: a pair is an inlier when
its reprojection error is within the 99.9 % quantile of a 2-D Gaussian of that sigma (3.72 sigma),
so a clean set loses a point in a thousand to the sampler and none to the final check
(:func:`calib_core.solver.finish._flag_outliers` rejects beyond 4 sigma). Memory and time are O(N)
per hypothesis; the number of hypotheses follows the inlier ratio, not N. Pixels are undistorted
first (the sampler is given the pinhole camera): the threshold is then in undistorted pixels, close
enough for a seed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import poselib

from calib_core.solver.initialisation import normalized_coordinates
from calib_core.solver.kernels.sample_consensus import sample_consensus
from calib_core.solver.kernels.subset_fit import FITTED, fit_subset_rounds
from calib_core.solver.problem import PoseProblem

INLIER_SIGMAS = 3.72  # sqrt of chi-square(2 dof) at 99.9 %
CONFIDENCE = 0.9999
MAX_HYPOTHESES = 10_000
MIN_HYPOTHESES = 20  # PoseLib's default of 1000 costs 2 ms even on a clean set
MIN_POINTS = 4
SAMPLED_FROM = 300
"""Beyond this many pairs the hypotheses are drawn and scored among this many of them."""


@dataclass(frozen=True)
class RobustSeed:
    """The sampler's pose ``(R (3, 3), t (3,) mm)`` and its inliers (n,) bool."""

    R: np.ndarray
    t: np.ndarray
    inliers: np.ndarray


def inlier_threshold_px(noise_px: float) -> float:
    return INLIER_SIGMAS * noise_px


def robust_seed(
    problem: PoseProblem, fu: float, fv: float, noise_px: float, order: np.ndarray | None = None, seed: int = 0
) -> RobustSeed | None:
    """A pose from the largest consistent subset of the pairs, or ``None`` (too few pairs, or no
    hypothesis with four inliers). ``order`` (n,) indices best first, when the pairs carry a
    confidence (detections): PROSAC draws from the best ones first."""
    n = problem.n_points
    if n < MIN_POINTS:
        return None
    intr = problem.intrinsics
    P, uv = problem.points_3d, problem.points_2d
    if intr.has_distortion:
        xy = normalized_coordinates(uv, intr, fu, fv)
        uv = np.column_stack([xy[:, 0] * fu + intr.cx, xy[:, 1] * fv + intr.cy])
    if order is not None:
        P, uv = P[order], uv[order]
    all_P, all_uv = P, uv
    if n > SAMPLED_FROM:
        # The hypotheses are drawn and scored among a subset (the most confident, else a seeded random draw): a
        # hypothesis scored on thousands of pairs costs as many times more and picks the same pose; the pose's
        # inliers are then counted over every pair.
        keep = (
            np.arange(SAMPLED_FROM) if order is not None else np.random.default_rng(seed).permutation(n)[:SAMPLED_FROM]
        )
        P, uv = P[keep], uv[keep]
    if order is None:
        R, t = np.empty((3, 3)), np.empty(3)
        within = np.empty(len(P), dtype=np.bool_)
        found = sample_consensus(
            np.ascontiguousarray(P, dtype=np.float64),
            np.ascontiguousarray(uv, dtype=np.float64),
            float(fu),
            float(fv),
            float(intr.cx),
            float(intr.cy),
            inlier_threshold_px(noise_px),
            CONFIDENCE,
            MIN_HYPOTHESES,
            MAX_HYPOTHESES,
            seed,
            R,
            t,
            within,
        )
        if found == 0:
            return None
        _locally_optimised(P, uv, R, t, fu, fv, intr.cx, intr.cy, inlier_threshold_px(noise_px), within)
        inliers = (
            np.flatnonzero(_within(all_P, all_uv, R, t, fu, fv, intr.cx, intr.cy, inlier_threshold_px(noise_px)))
            if n > SAMPLED_FROM
            else np.flatnonzero(within)
        )
        if len(inliers) < 4:
            return None
        mask = np.zeros(n, dtype=bool)
        mask[inliers] = True
        return RobustSeed(R, t, mask)
    camera = {"model": "PINHOLE", "width": intr.width, "height": intr.height, "params": [fu, fv, intr.cx, intr.cy]}
    options = {
        "max_reproj_error": inlier_threshold_px(noise_px),
        "success_prob": CONFIDENCE,
        "max_iterations": MAX_HYPOTHESES,
        "min_iterations": MIN_HYPOTHESES,
        "seed": seed,
        "progressive_sampling": order is not None,
    }
    try:
        pose, info = poselib.estimate_absolute_pose(
            np.ascontiguousarray(uv, dtype=np.float64),
            np.ascontiguousarray(P, dtype=np.float64),
            camera,
            options,
            {"max_iterations": 0},
        )
    except (RuntimeError, ValueError):
        return None
    R = np.asarray(pose.R, dtype=float)
    t = np.asarray(pose.t, dtype=float).reshape(3)
    if not (np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
        return None
    if n > SAMPLED_FROM:
        inliers = np.flatnonzero(_within(all_P, all_uv, R, t, fu, fv, intr.cx, intr.cy, inlier_threshold_px(noise_px)))
    else:
        inliers = np.flatnonzero(np.asarray(info.get("inliers", []), dtype=bool))
    if len(inliers) < 4:
        return None
    mask = np.zeros(n, dtype=bool)
    mask[order[inliers] if order is not None else inliers] = True
    return RobustSeed(R, t, mask)


def _locally_optimised(P, uv, R, t, fu, fv, cx, cy, threshold_px, within) -> None:
    """The sampled pose fitted by least squares to the pairs within ``threshold_px`` of it, and again to those
    within it then (LO-RANSAC's local optimisation, at most three rounds; pinhole, ``uv`` without the lens's
    distortion): ``R``, ``t`` and ``within`` updated in place, left as they were when no fit came of it. A P3P pose
    from three noisy pairs misses some good pairs by more than the threshold; fitted to its inliers it finds them,
    and the consensus over every pair starts from nearly its final set."""
    R2, t2, f = R.copy(), t.copy(), np.array([fu, fv], dtype=float)
    within2 = within.copy()
    r, J = np.empty((len(P), 2)), np.empty((len(P), 2, 6))
    code, _, _ = fit_subset_rounds(
        np.ascontiguousarray(P, dtype=np.float64),
        np.ascontiguousarray(uv, dtype=np.float64),
        R2,
        t2,
        f,
        float(cx),
        float(cy),
        np.zeros(5),
        False,
        within2,
        float(threshold_px),
        3,
        100,
        3,
        r,
        J,
    )
    if code == FITTED and np.all(np.isfinite(R2)) and np.all(np.isfinite(t2)) and within2.sum() >= within.sum():
        R[:, :], t[:], within[:] = R2, t2, within2


def _within(P, uv, R, t, fu, fv, cx, cy, threshold_px) -> np.ndarray:
    """Which pairs (n,) bool the pose ``(R, t)`` puts in front of the camera and within ``threshold_px`` of their
    pixels (pinhole; ``uv`` already without the lens's distortion)."""
    X = P @ R.T + t
    z = X[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        du = fu * X[:, 0] / z + cx - uv[:, 0]
        dv = fv * X[:, 1] / z + cy - uv[:, 1]
        return (z > 0.0) & (du * du + dv * dv <= threshold_px * threshold_px)
