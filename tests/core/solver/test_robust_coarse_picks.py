"""The robust mode with hand picks coarser than the noise model, and with few pairs.

Robust mode judged every pair against 0.5 px: 7 clean pairs picked at 2 px had good pairs rejected in 182 of
200 scenes (the pose up to 84 mm from the plain solve's), and 7 hand picks on a photo failed. It now
measures the picks' scale when the pairs allow it, admits a left-out pair by the same test the misfit check
uses, and with few pairs calls the answer ambiguous when a different pair could be the mis-pick."""

from __future__ import annotations

import numpy as np
import pytest

from calib_core.solver import solve_pose
from calib_core.solver.consensus import rival_consensus
from calib_core.solver.pick_scale import pick_scale_px
from calib_core.solver.problem import make_problem
from tests.core.solver.scenes import PINHOLE_CAMERA, pixels, pose_error, random_points, random_pose

CAM = PINHOLE_CAMERA


def _clean(seed: int, n: int, noise: float, count: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        T, P = random_pose(rng), random_points(rng, n)
        yield T, P, pixels(P, T, CAM, noise_px=noise, rng=rng)


@pytest.mark.parametrize("n", [7, 10, 20])
def test_robust_on_clean_coarse_picks_gives_the_plain_answer(n):
    plain_ok = robust_ok = 0
    for _, P, uv in _clean(100 + n, n, 2.0, 60):
        plain, robust = solve_pose(P, uv, CAM), solve_pose(P, uv, CAM, robust=True)
        robust_ok += robust.status.value == "ok" and not robust.outliers.any()
        if plain.status.value == "ok":
            plain_ok += 1
            assert robust.status.value == "ok" and not robust.outliers.any(), (
                robust.reason,
                np.flatnonzero(robust.outliers),
            )
            mm, deg = pose_error(robust.obj2cam, plain.obj2cam)
            assert mm < 1e-6 and deg < 1e-6
    assert robust_ok >= plain_ok and robust_ok >= 58  # the plain solve refuses some 2 px sets (RMS over 5 x 0.5 px)


def test_the_picks_scale_is_measured_and_a_mis_pick_does_not_raise_it():
    rng = np.random.default_rng(5)
    T, P = random_pose(rng), random_points(rng, 20)
    coarse = pixels(P, T, CAM, noise_px=2.0, rng=rng)
    assert 1.2 < pick_scale_px(make_problem(P, coarse, CAM), CAM.fu, CAM.fv) < 2.6  # low by about a tenth (module)
    fine = pixels(P, T, CAM, noise_px=0.5, rng=rng)
    fine[3] += (12.0, 0.0)  # a 12 px mis-pick: an RMS-based scale would be 2.7 px and hide it
    assert pick_scale_px(make_problem(P, fine, CAM), CAM.fu, CAM.fv) < 0.75
    s = solve_pose(P, fine, CAM, robust=True)
    assert s.status.value == "ok" and np.flatnonzero(s.outliers).tolist() == [3]


def test_too_few_pairs_to_measure_a_scale():
    rng = np.random.default_rng(6)
    T, P = random_pose(rng), random_points(rng, 5)
    assert pick_scale_px(make_problem(P, pixels(P, T, CAM, noise_px=2.0, rng=rng), CAM), CAM.fu, CAM.fv) is None


def _one_off(seed: int, n: int, count: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        T, P = random_pose(rng), random_points(rng, n)
        uv = pixels(P, T, CAM, noise_px=0.3, rng=rng)
        bad = int(rng.integers(n))
        truth_fit = solve_pose(np.delete(P, bad, 0), np.delete(uv, bad, 0), CAM, sigma_px=0.3)
        d = rng.normal(size=2)
        uv[bad] += d / np.linalg.norm(d) * rng.uniform(5, 20)
        yield T, P, uv, bad, np.linalg.norm(truth_fit.uncertainty.std_t_obj2cam_mm)


def test_with_five_pairs_a_pair_that_another_could_replace_is_not_called_the_mis_pick():
    """5 pairs, one 5-20 px off: a least-squares pose through four can absorb the mis-pick while a good pair is
    left out (a pose 10 mm wrong, ``ok``, 5 of 300 scenes). Such a set has a rival of the same size: ambiguous."""
    wrong_ok = ambiguous = 0
    for T, P, uv, bad, std in _one_off(6, 5, 300):
        s = solve_pose(P, uv, CAM, robust=True)
        ambiguous += s.status.value == "ambiguous"
        if s.status.value == "ambiguous" and "could be the pick that is off" in s.reason:
            named = {int(n) for n in s.reason.split(":")[0].replace("points", "").replace("point", "").split(",")}
            assert bad + 1 in named, (bad + 1, s.reason)  # the mis-pick is among the pairs it names
        if s.status.value == "ok":
            wrong_ok += pose_error(s.obj2cam, T)[0] > 5 * std + 0.5
    # one scene of 300 is left: the mis-pick at a point of such leverage (h = 0.97) that no pick can check it;
    # the plain solve calls that scene ok as well
    assert wrong_ok <= 1 and ambiguous > 40


def test_a_rival_is_the_same_size_swap_that_fits():
    for T, P, uv, bad, _ in _one_off(6, 5, 300):
        s = solve_pose(P, uv, CAM, robust=True)
        if s.status.value != "ambiguous" or not s.outliers.any():
            continue
        # the set it chose, refitted, has rivals; each keeps four pairs and rejects another one
        from calib_core.solver.consensus import consensus_refine

        problem = make_problem(P, uv, CAM)
        chosen = consensus_refine(
            problem, s.obj2cam[:3, :3], s.obj2cam[:3, 3], CAM.fu, CAM.fv, 2.0, inliers=~s.outliers
        )
        rivals = rival_consensus(problem, chosen, 0.5)
        assert rivals and all(
            r.inliers.sum() == chosen.inliers.sum() and not np.array_equal(r.inliers, chosen.inliers) for r in rivals
        )
        return
    pytest.fail("no ambiguous scene with a rejected pair among 300")
