"""A look fused with the calibrated model: known answers of the weighted mean, the disagreement that
keeps the robot where the model puts it, the correction that lands where the fused displacement says,
and the camera-to-TCP lever arm checked against composing the transforms."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.calibration.end_effector import EndEffectorEstimate
from calib_core.calibration.look_fusion import fuse_look, tcp_covariance_from_camera
from calib_core.frames import make_transform, pose_difference

TCP = make_transform(Rotation.from_euler("xyz", [10, -20, 30], degrees=True).as_matrix(), [900.0, -300.0, 1200.0])


def _look(displacement_mm, rotation_deg, sigma_mm, sigma_deg):
    d, r = np.asarray(displacement_mm, float), np.asarray(rotation_deg, float)
    measured = make_transform(Rotation.from_rotvec(np.radians(r)).as_matrix() @ TCP[:3, :3], TCP[:3, 3] + d)
    cov = np.diag([sigma_mm**2] * 3 + [sigma_deg**2] * 3)
    return EndEffectorEstimate(
        None, np.eye(4), np.eye(4), np.eye(4), TCP, measured, d, r, np.full(3, sigma_mm), np.full(3, sigma_deg), cov
    )


def _model(sigma_mm, sigma_deg):
    return np.diag([sigma_mm**2] * 3 + [sigma_deg**2] * 3)


def test_equal_uncertainties_take_half_the_look_and_shrink_the_sigma():
    fused = fuse_look(_look([0.06, -0.03, 0.0], [0.01, 0.0, -0.01], 0.05, 0.01), _model(0.05, 0.01))
    assert fused.agree
    assert np.allclose(fused.displacement_mm, [0.03, -0.015, 0.0]) and np.allclose(
        fused.rotation_deg, [0.005, 0.0, -0.005]
    )
    assert np.allclose(np.sqrt(np.diag(fused.covariance)), [0.05 / np.sqrt(2)] * 3 + [0.01 / np.sqrt(2)] * 3)
    assert np.allclose(fused.look_weight, 0.5)


def test_the_more_certain_side_wins():
    look = _look([0.08, 0.0, 0.0], [0.0, 0.02, 0.0], 0.01, 0.002)
    assert fuse_look(look, _model(1.0, 0.2)).displacement_mm[0] == pytest.approx(
        0.08, rel=1e-3
    )  # an uncalibrated model: the look
    assert (
        abs(fuse_look(_look([0.01, 0, 0], [0, 0, 0], 1.0, 0.2), _model(0.01, 0.002)).displacement_mm[0]) < 1e-5
    )  # a noisy look: the model


def test_a_look_that_disagrees_is_not_used_and_says_why():
    fused = fuse_look(_look([0.5, 0.0, 0.0], [0.0, 0.0, 0.0], 0.03, 0.01), _model(0.03, 0.01))
    assert not fused.agree and np.allclose(fused.delta_base, np.eye(4))
    assert "sigma from the calibrated model" in fused.message and "not used" in fused.message
    with pytest.raises(ValueError, match="no covariance"):
        fuse_look(replace(_look([0, 0, 0], [0, 0, 0], 0.03, 0.01), covariance=None), _model(0.03, 0.01))


def test_the_correction_puts_the_tcp_at_the_fused_displacement():
    fused = fuse_look(_look([0.04, 0.02, -0.06], [0.01, -0.02, 0.015], 0.04, 0.01), _model(0.04, 0.01))
    d, r = pose_difference(fused.delta_base @ TCP, TCP)
    assert np.allclose(d, fused.displacement_mm, atol=1e-9) and np.allclose(r, fused.rotation_deg, atol=1e-9)


def test_the_lever_arm_matches_composed_transforms():
    """A second way: turn and shift the camera by a small step, compose the TCP through it, compare
    the TCP's change with the linear map the covariance uses."""
    cam = make_transform(Rotation.from_euler("xyz", [-100, 10, 60], degrees=True).as_matrix(), [800.0, -200.0, 1300.0])
    tcp2cam = make_transform(Rotation.from_euler("x", 180, degrees=True).as_matrix(), [0.0, -60.0, 150.0])
    rng = np.random.default_rng(0)
    for _ in range(5):
        step = rng.normal(size=6) * [0.01, 0.01, 0.01, 0.01, 0.01, 0.01]  # mm, mrad
        moved = make_transform(Rotation.from_rotvec(step[3:] / 1000.0).as_matrix() @ cam[:3, :3], cam[:3, 3] + step[:3])
        d, r = pose_difference(moved @ tcp2cam, cam @ tcp2cam)
        # The covariance of a point mass at ``step`` is step step^T: its map is A step (A step)^T.
        C = tcp_covariance_from_camera(np.outer(step, step), cam, tcp2cam)
        mapped = np.r_[d, r]
        assert np.allclose(C, np.outer(mapped, mapped), atol=1e-9 * max(1.0, np.abs(C).max()))


def test_the_placement_of_the_component_widens_the_models_prior_in_position_only():
    """The look sees the part where it stands, the model aims where the survey put it: with the
    survey's sigma added to the model's, a look 0.12 mm off a 0.01 mm model agrees and weighs more,
    and the rotation's weight is unchanged (the known answer of the scalar update per axis)."""
    look = _look([0.12, 0.0, 0.0], [0.002, 0.0, 0.0], 0.02, 0.005)
    assert not fuse_look(look, _model(0.01, 0.005)).agree
    fused = fuse_look(look, _model(0.01, 0.005), placement_sigma_mm=0.05)
    assert fused.agree
    prior = 0.01**2 + 0.05**2
    assert fused.look_weight[0] == pytest.approx(prior / (prior + 0.02**2))
    assert fused.look_weight[3] == pytest.approx(0.5)
    assert fused.displacement_mm[0] == pytest.approx(0.12 * prior / (prior + 0.02**2))
