"""The reported 1-sigma against the spread of the actual errors over many noisy solves."""

import numpy as np
import pytest

from calib_core.solver import solve_pose, solve_pose_batch

from tests.core.solver.scenes import GRIPPER_CAMERA, pixels, random_points, random_pose


def test_batch_sigma_matches_monte_carlo_spread():
    rng = np.random.default_rng(4)
    truth = random_pose(rng)
    P = random_points(rng, 6)
    exact = pixels(P, truth)
    b = 400
    uv = exact[None] + rng.normal(0, 0.5, (b, 6, 2))
    res = solve_pose_batch(np.broadcast_to(P, (b, 6, 3)), uv, GRIPPER_CAMERA, sigma_px=0.5)
    assert res.converged.all()
    errors = res.obj2cam[:, :3, 3] - truth[:3, 3]
    actual = errors.std(axis=0)
    reported = res.std_t_obj2cam_mm.mean(axis=0)
    assert np.all(np.abs(reported / actual - 1) < 0.15), (reported, actual)
    centres = -np.einsum("bji,bj->bi", res.obj2cam[:, :3, :3], res.obj2cam[:, :3, 3])
    assert np.all(np.abs(res.std_camera_position_mm.mean(axis=0) / centres.std(axis=0) - 1) < 0.15)


def test_single_and_batch_agree():
    rng = np.random.default_rng(9)
    truth = random_pose(rng)
    P = random_points(rng, 7)
    uv = pixels(P, truth, noise_px=0.5, rng=rng)
    single = solve_pose(P, uv, GRIPPER_CAMERA)
    batch = solve_pose_batch(P[None], uv[None], GRIPPER_CAMERA)
    assert np.allclose(batch.obj2cam[0], single.obj2cam, atol=1e-8)
    assert batch.rms_px[0] == pytest.approx(np.sqrt(np.mean(single.residual_norms_px**2)), rel=1e-9)
    assert np.allclose(batch.std_t_obj2cam_mm[0], single.uncertainty.std_t_obj2cam_mm, rtol=1e-6)
    assert np.allclose(batch.std_camera_position_mm[0], single.uncertainty.std_camera_position_mm, rtol=1e-6)


def test_without_redundancy_the_default_sigma_is_used():
    rng = np.random.default_rng(1)
    truth = random_pose(rng)
    P = random_points(rng, 4)
    sol = solve_pose(P, pixels(P, truth), GRIPPER_CAMERA.with_focal(1100, 1100), estimate_focal=True)
    assert sol.uncertainty.sigma_source == "default"
    assert sol.uncertainty.sigma_px == 0.5
    # Unknown focal lengths cost a lot of position accuracy compared with a known camera.
    known = solve_pose(P, pixels(P, truth), GRIPPER_CAMERA, sigma_px=0.5)
    assert np.linalg.norm(sol.uncertainty.std_t_obj2cam_mm) > 3 * np.linalg.norm(known.uncertainty.std_t_obj2cam_mm)
