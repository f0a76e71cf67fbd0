"""solve_pose end to end: project known poses, solve without a guess, compare (round trips),
on fixed scenes and on random well-conditioned ones (hypothesis)."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from calib_core.frames import make_transform
from calib_core.solver import SolveStatus, refine_pose, solve_pose

from tests.core.solver.scenes import GRIPPER_CAMERA, PINHOLE_CAMERA, pixels, pose_error, random_points, random_pose


@pytest.mark.parametrize("n", [4, 6, 20])
def test_exact_pixels_give_the_true_pose_with_distortion(n):
    rng = np.random.default_rng(n)
    truth = random_pose(rng)
    P = random_points(rng, n)
    sol = solve_pose(P, pixels(P, truth), GRIPPER_CAMERA)
    assert sol.status is SolveStatus.OK, sol.reason
    dt, dr = pose_error(sol.obj2cam, truth)
    assert dt < 1e-6 and dr < 1e-7
    assert sol.rms_px < 1e-6
    assert np.allclose(sol.camera_position_mm, -truth[:3, :3].T @ truth[:3, 3], atol=1e-6)


def test_coplanar_points_are_solved_and_the_mirror_pose_is_not_preferred():
    rng = np.random.default_rng(3)
    truth = random_pose(rng)
    P = random_points(rng, 5, planar=True)
    sol = solve_pose(P, pixels(P, truth, noise_px=0.3, rng=rng), GRIPPER_CAMERA)
    assert sol.status in (SolveStatus.OK, SolveStatus.AMBIGUOUS)
    dt, dr = pose_error(sol.obj2cam, truth)
    assert dt < 3.0 and dr < 0.5


def test_noisy_pixels_residuals_and_sigma_estimate():
    rng = np.random.default_rng(11)
    truth = random_pose(rng)
    P = random_points(rng, 12)
    sol = solve_pose(P, pixels(P, truth, noise_px=0.5, rng=rng), GRIPPER_CAMERA)
    assert sol.ok
    assert 0.2 < sol.rms_px < 0.8
    assert sol.uncertainty.sigma_source == "estimated"
    assert 0.3 < sol.uncertainty.sigma_px < 0.8
    assert sol.residuals_px.shape == (12, 2)
    assert np.all(np.isfinite(sol.leave_one_out_px))
    assert np.all(sol.leave_one_out_px >= sol.residual_norms_px - 1e-12)  # dropping a point never fits it better


def test_focal_lengths_are_estimated_from_four_or_more_points():
    rng = np.random.default_rng(5)
    truth = random_pose(rng, distance_mm=400)
    P = random_points(rng, 8, size_mm=200)
    true_camera = PINHOLE_CAMERA
    guess = true_camera.with_focal(true_camera.fu * 1.05, true_camera.fv * 0.96)
    sol = solve_pose(P, pixels(P, truth, true_camera), guess, estimate_focal=True)
    assert sol.ok, sol.reason
    assert sol.fu == pytest.approx(true_camera.fu, rel=1e-8)
    assert sol.fv == pytest.approx(true_camera.fv, rel=1e-8)
    assert sol.uncertainty.std_fu_px is not None


def test_three_points_are_ambiguous_and_ranked_by_the_prior():
    rng = np.random.default_rng(2)
    for _ in range(5):
        truth = random_pose(rng)
        P = random_points(rng, 3)
        uv = pixels(P, truth)
        sol = solve_pose(P, uv, GRIPPER_CAMERA, prior=truth @ make_transform(np.eye(3), [2.0, -1.0, 3.0]))
        if len(sol.candidates) < 2:
            continue  # P3P has a single real root for this configuration
        assert sol.status is SolveStatus.AMBIGUOUS
        assert pose_error(sol.obj2cam, truth)[0] < 1e-6  # the candidate closest to the prior comes first
        assert sol.candidates[0].distance_to_prior_mm < sol.candidates[1].distance_to_prior_mm
        assert any("no redundancy" in w for w in sol.warnings)
        return
    pytest.fail("no ambiguous 3-point configuration in five tries")


def test_a_mis_click_fails_plainly_and_robust_mode_flags_it():
    rng = np.random.default_rng(21)
    truth = random_pose(rng)
    P = random_points(rng, 8)
    uv = pixels(P, truth, noise_px=0.3, rng=rng)
    uv[4] += [25.0, -18.0]  # point 5 clicked on the wrong corner
    plain = solve_pose(P, uv, GRIPPER_CAMERA)
    assert plain.status is SolveStatus.FAILED
    assert "point 5" in plain.reason
    assert int(np.nanargmax(plain.leave_one_out_px)) == 4
    robust = solve_pose(P, uv, GRIPPER_CAMERA, robust=True)
    assert robust.ok, robust.reason
    assert robust.outliers.tolist() == [i == 4 for i in range(8)]
    dt, dr = pose_error(robust.obj2cam, truth)
    assert dt < 2.0 and dr < 0.3
    assert any("point 5" in w for w in robust.warnings)


def test_refine_pose_finds_the_minimum_nearest_its_start():
    rng = np.random.default_rng(8)
    truth = random_pose(rng)
    P = random_points(rng, 6)
    start = truth @ make_transform(np.eye(3), [30.0, -20.0, 40.0])
    sol = refine_pose(P, pixels(P, truth), GRIPPER_CAMERA, start)
    assert sol.ok
    assert pose_error(sol.obj2cam, truth)[0] < 1e-6


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(4, 12))
def test_random_well_conditioned_scenes_round_trip(seed, n):
    rng = np.random.default_rng(seed)
    truth = random_pose(rng)
    P = random_points(rng, n)
    uv = pixels(P, truth)
    if not GRIPPER_CAMERA.contains(uv, margin_px=5).all():
        return  # points off the image are no calibration an operator could make
    sol = solve_pose(P, uv, GRIPPER_CAMERA)
    assert sol.status in (SolveStatus.OK, SolveStatus.AMBIGUOUS)
    assert any(pose_error(c.obj2cam, truth)[0] < 1e-5 for c in sol.candidates)
    if n >= 6:
        assert sol.ok and pose_error(sol.obj2cam, truth)[0] < 1e-5
