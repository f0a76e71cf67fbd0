"""The robust mode at scale: a sampler instead of every triplet, O(n) memory, and a threshold that
follows the pick noise (a clean set never fails)."""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.solver import solve_pose
from calib_core.solver.initialisation import spread_triplets

CAM = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960)


def _scene(rng, n, outlier_share=0.0, noise_px=0.5):
    T = make_transform(
        Rotation.from_rotvec(rng.normal(0, 0.3, 3)).as_matrix(), [rng.uniform(-40, 40), rng.uniform(-30, 30), 500.0]
    )
    P = rng.uniform(-75, 75, (n, 3))
    uv = project_points(P, T, CAM) + rng.normal(0, noise_px, (n, 2))
    bad = rng.random(n) < outlier_share
    uv[bad] = rng.uniform([0, 0], [1280, 960], (int(bad.sum()), 2))
    return T, P, uv, bad


def test_five_thousand_pairs_with_30_percent_outliers_are_sorted_out_in_little_memory():
    rng = np.random.default_rng(3)
    T, P, uv, bad = _scene(rng, 5000, 0.3)
    tracemalloc.start()
    solution = solve_pose(P, uv, CAM, robust=True, sigma_px=0.5)
    peak_mb = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    assert solution.status.value == "ok"
    far_off = (
        np.linalg.norm(uv - project_points(P, T, CAM), axis=1) > 4 * 0.5 * 1.2
    )  # drawn as outliers and far from the truth
    assert (
        np.array_equal(solution.outliers[far_off], np.ones(far_off.sum(), bool)) and not solution.outliers[~bad].any()
    )
    assert np.linalg.norm(solution.obj2cam[:3, 3] - T[:3, 3]) < 0.1
    assert peak_mb < 200  # all triplets of 5000 points would be 2e10 of them


def test_triplets_for_many_points_are_bounded_and_spread():
    rng = np.random.default_rng(0)
    P = rng.uniform(-100, 100, (5914, 3))
    t0 = time.process_time()
    triplets = spread_triplets(P, limit=6)
    assert time.process_time() - t0 < 1.0  # was: every combination, killed at 22 GB
    assert len(triplets) == 6 and all(len(set(t)) == 3 for t in triplets)
    areas = [np.linalg.norm(np.cross(P[j] - P[i], P[k] - P[i])) / 2 for i, j, k in triplets]
    assert min(areas) > 0.25 * (200 * 200 / 2)  # large triangles, not a random thin one
    small = rng.uniform(-1, 1, (7, 3))
    assert len(spread_triplets(small, limit=100)) == 35  # few points: every triplet


@pytest.mark.parametrize("n", [6, 20, 200])
def test_a_clean_set_never_fails_in_robust_mode(n):
    rng = np.random.default_rng(n)
    for _ in range(30):
        T, P, uv, _ = _scene(rng, n)
        solution = solve_pose(P, uv, CAM, robust=True, sigma_px=0.5)
        assert solution.status.value == "ok", solution.reason
        assert solution.outliers.sum() <= max(1, n // 100)
