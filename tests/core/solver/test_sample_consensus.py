"""The robust sampler's compiled hypotheses (MSAC on P3P over random triplets): the pose it keeps explains the good
pairs and leaves out the wrong ones, the same for the same seed, and it stops early on a clean set."""

import numpy as np
import pytest

from calib_core.frames import pose_difference
from calib_core.solver.kernels.sample_consensus import _needed, sample_consensus
from tests.core.solver.scenes import PINHOLE_CAMERA, pixels, random_points, random_pose

CAM = PINHOLE_CAMERA


def _sample(P, uv, seed=0, min_hypotheses=20, max_hypotheses=10_000):
    R, t, inliers = np.empty((3, 3)), np.empty(3), np.empty(len(P), dtype=np.bool_)
    count = sample_consensus(
        P, uv, CAM.fu, CAM.fv, CAM.cx, CAM.cy, 3.72 * 0.5, 0.9999, min_hypotheses, max_hypotheses, seed, R, t, inliers
    )
    obj2cam = np.eye(4)
    obj2cam[:3, :3], obj2cam[:3, 3] = R, t
    return count, obj2cam, inliers


@pytest.mark.parametrize("n, share", [(8, 0.25), (20, 0.2), (60, 0.5), (300, 0.3)])
def test_the_kept_pose_explains_the_good_pairs_and_not_the_wrong_ones(n, share):
    rng = np.random.default_rng(n)
    for _ in range(20):
        T, P = random_pose(rng), random_points(rng, n)
        uv = pixels(P, T, CAM, noise_px=0.5, rng=rng)
        wrong = rng.choice(n, int(share * n), replace=False)
        uv[wrong] = rng.uniform([0, 0], [CAM.width, CAM.height], (len(wrong), 2))
        count, obj2cam, inliers = _sample(P, uv)
        good = np.ones(n, dtype=bool)
        good[wrong] = False
        # a pose from three noisy pairs: near the truth, most good pairs within the threshold, no wrong one
        moved_mm, turned_deg = pose_difference(obj2cam, T)
        assert np.linalg.norm(moved_mm) < 20.0 and np.linalg.norm(turned_deg) < 2.0
        assert count == inliers.sum() and not (inliers & ~good).any() and inliers[good].mean() > 0.6


def test_the_same_seed_gives_the_same_pose_and_another_may_not():
    rng = np.random.default_rng(3)
    T, P = random_pose(rng), random_points(rng, 30)
    uv = pixels(P, T, CAM, noise_px=0.5, rng=rng)
    uv[:9] = rng.uniform([0, 0], [CAM.width, CAM.height], (9, 2))
    a, b = _sample(P, uv, seed=7), _sample(P, uv, seed=7)
    assert a[0] == b[0] and np.array_equal(a[1], b[1]) and np.array_equal(a[2], b[2])


def test_the_draws_stop_at_the_confidence_the_inlier_share_allows():
    # (1 - w^3)^k <= 1 - confidence: all inliers need none beyond the minimum, 80 % about 13, 50 % about 70
    assert _needed(20, 20, 0.9999, 3) == 0
    assert _needed(16, 20, 0.9999, 3) == int(np.ceil(np.log(1e-4) / np.log(1 - 0.8**3)))
    assert _needed(10, 20, 0.9999, 3) == int(np.ceil(np.log(1e-4) / np.log(1 - 0.5**3)))
    assert _needed(0, 20, 0.9999, 3) > 10_000
    # a set of only wrong pairs gives nothing trustworthy, and the draws end at the limit
    rng = np.random.default_rng(4)
    P = random_points(rng, 12)
    uv = rng.uniform([0, 0], [CAM.width, CAM.height], (12, 2))
    count, _, inliers = _sample(P, uv, max_hypotheses=200)
    assert count == inliers.sum() and count <= 4
