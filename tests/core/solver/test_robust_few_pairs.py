"""The robust solve with few pairs: 5 pairs, one 50-200 px off, were fitted as three exact pairs
with two good ones rejected and called ``ok`` up to 550 mm wrong (64 of 200 scenes). An answer called ok
must now be right; one that the pairs cannot decide is ambiguous or failed, never ok."""

from __future__ import annotations

import numpy as np
import poselib
import pytest

from calib_core.solver import solve_pose
from calib_core.solver.consensus import consensus_refine, msac_score
from calib_core.solver.problem import make_problem
from tests.core.solver.scenes import PINHOLE_CAMERA, pixels, pose_error, random_points, random_pose


def _scenes(seed: int, n: int, count: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        T, P = random_pose(rng), random_points(rng, n)
        uv = pixels(P, T, PINHOLE_CAMERA, noise_px=0.3, rng=rng)
        bad = int(rng.integers(n))
        d = rng.normal(size=2)
        uv[bad] += d / np.linalg.norm(d) * rng.uniform(50, 200)
        yield T, P, uv, bad


@pytest.mark.parametrize("n", [5, 6, 8])
def test_one_mis_click_among_few_pairs_is_never_an_ok_wrong_pose(n):
    ok = 0
    for T, P, uv, bad in _scenes(n, n, 150):
        s = solve_pose(P, uv, PINHOLE_CAMERA, robust=True)
        if s.status.value != "ok":
            continue
        ok += 1
        # the mis-click is the one flagged, and the pose is the least-squares pose of the good pairs alone
        assert s.outliers[bad] and s.outliers.sum() == 1, (np.flatnonzero(s.outliers), bad)
        good = solve_pose(np.delete(P, bad, 0), np.delete(uv, bad, 0), PINHOLE_CAMERA)
        mm, deg = pose_error(s.obj2cam, good.obj2cam)
        assert mm < 0.01 and deg < 1e-3 and pose_error(s.obj2cam, T)[0] < 30.0
    assert ok >= 0.9 * 150


def test_poselib_agrees_on_the_ok_poses():
    """The same scenes through PoseLib's own LO-RANSAC: where we say ok, its pose is ours within noise."""
    for T, P, uv, _ in _scenes(11, 6, 40):
        s = solve_pose(P, uv, PINHOLE_CAMERA, robust=True)
        if s.status.value != "ok":
            continue
        cam = {
            "model": "PINHOLE",
            "width": 1280,
            "height": 960,
            "params": [PINHOLE_CAMERA.fu, PINHOLE_CAMERA.fv, PINHOLE_CAMERA.cx, PINHOLE_CAMERA.cy],
        }
        pose, _ = poselib.estimate_absolute_pose(uv, P, cam, {"max_reproj_error": 2.0}, {})
        theirs = np.eye(4)
        theirs[:3, :3], theirs[:3, 3] = pose.R, pose.t
        assert pose_error(s.obj2cam, theirs)[0] < 5.0


def test_a_right_seed_stays_right_where_hubers_loss_walked_170_mm_away():
    T, P, uv, bad = list(_scenes(0, 5, 2))[1]
    problem = make_problem(P, uv, PINHOLE_CAMERA)
    fit = consensus_refine(problem, T[:3, :3], T[:3, 3], PINHOLE_CAMERA.fu, PINHOLE_CAMERA.fv, 2.0)
    e = np.linalg.norm(fit.newton.residuals, axis=1)
    assert fit.newton.residuals.shape == (5, 2) and e[bad] > 40 and np.all(np.delete(e, bad) < 2.0)
    assert pose_error(fit.obj2cam, T)[0] < 10.0
    assert msac_score(fit.newton.residuals, 2.0) == pytest.approx(4.0 + np.sum(np.delete(e, bad) ** 2))


def test_three_agreeing_pairs_are_not_an_answer():
    rng = np.random.default_rng(5)
    T, P = random_pose(rng), random_points(rng, 5)
    uv = pixels(P, T, PINHOLE_CAMERA, noise_px=0.3, rng=rng)
    uv[[1, 3]] += [[90.0, -40.0], [-60.0, 120.0]]  # two of five off: three left, which fit exactly whatever they are
    s = solve_pose(P, uv, PINHOLE_CAMERA, robust=True)
    assert (
        s.status.value == "failed" and "only 3 pairs agree" in s.reason and "too few to check one another" in s.reason
    )


def test_two_subsets_that_fit_equally_well_make_an_ambiguous_answer():
    """A scene where a second four of the five pairs (the mis-click among them) fit within noise too: it
    was called ok 33 mm off; now both poses are offered, and one of them is the truth."""
    found = None
    for T, P, uv, bad in _scenes(3, 5, 200):
        s = solve_pose(P, uv, PINHOLE_CAMERA, robust=True)
        if s.status.value == "ambiguous":
            found = (T, s)
            break
    assert found is not None
    T, s = found
    assert len(s.candidates) >= 2 and min(pose_error(c.obj2cam, T)[0] for c in s.candidates) < 10.0


def test_a_rival_four_out_of_reach_of_the_chosen_pose_still_makes_it_ambiguous():
    """Five pairs, the first thrown 220 px off: a pose 80 mm from the truth fits it and three good ones within
    0.3 px, while the four good pairs fit the truth at 0.9 px. From the wrong pose the good four's own minimum
    was out of reach, so no rival was found and the wrong pose was called ok (1 scene in about 12,000 of the
    reliability bench). Their own P3P roots find it: both explain four pairs, so the answer is ambiguous."""
    from calib_core.camera.intrinsics import Intrinsics

    camera = Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960)
    P = np.array(
        [
            [-35.905896, 52.055352, -21.071675],
            [12.041144, 49.739748, 34.206684],
            [24.547664, 6.219168, 37.769843],
            [-14.902368, -56.907612, 53.323548],
            [-12.253889, -22.164908, 56.784119],
        ]
    )
    uv = np.array(
        [
            [793.334861, 496.300391],
            [775.661902, 587.054799],
            [770.6505, 515.046118],
            [664.426848, 400.261524],
            [697.674255, 453.172955],
        ]
    )
    truth_t = np.array([23.228729075, 37.891095468, 529.898783715])
    s = solve_pose(P, uv, camera, robust=True)
    assert s.status.value != "ok" or np.linalg.norm(s.obj2cam[:3, 3] - truth_t) < 5.0
    assert s.status.value == "ambiguous"
    assert any(np.linalg.norm(c.obj2cam[:3, 3] - truth_t) < 5.0 for c in s.candidates)  # the truth is among them


def test_a_consensus_of_four_that_two_poses_fit_is_ambiguous_not_ok():
    """Seven pairs, three of them thrown anywhere in the image: the four good ones agree, and two poses 32 mm apart
    fit them both within the noise (0.35 px). The robust solve found one and called it ok, 35 mm from the truth
    (the bench's held-out scene); the consensus's own pairs, solved alone, show both: the answer is ambiguous, and the
    right pose is among its candidates."""
    from bench.solver_reliability import _scene
    from bench.solver_scenes import CAM

    rng = np.random.default_rng(5)
    for _ in range(76):  # the 76th scene of the bench's draw (seed 5, N = 7, 3 outliers)
        T, P, uv = _scene(rng, 7)
        bad = rng.choice(7, 3, replace=False)
        uv[bad] = rng.uniform([0, 0], [CAM.width, CAM.height], (3, 2))
    s = solve_pose(P, uv, CAM, robust=True)
    assert s.status.value == "ambiguous", (s.status, s.reason)
    errors = sorted(float(np.linalg.norm(c.obj2cam[:3, 3] - T[:3, 3])) for c in s.candidates)
    assert errors[0] < 5.0 and errors[-1] > 30.0, errors
    good = np.setdiff1d(np.arange(7), bad)
    assert sorted(np.flatnonzero(~np.asarray(s.outliers, bool)).tolist()) == good.tolist()
