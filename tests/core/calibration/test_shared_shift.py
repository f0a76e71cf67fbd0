"""The image points' shared error carried into a look's covariance: the known answer of a common
shift on a target facing the camera (its origin moves sideways by the shift times depth over focal
length) and a look's sigmas that grow with it."""

import numpy as np
import pytest

from calib_core.calibration.end_effector import shared_shift_covariance
from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform

LENS = Intrinsics(1120.0, 1116.0, 644.7, 476.3, 1280, 960)


def test_a_common_shift_moves_a_facing_target_sideways_by_shift_times_depth_over_focal():
    rng = np.random.default_rng(2)
    points = np.column_stack([rng.uniform(-60, 60, 12), rng.uniform(-40, 40, 12), np.zeros(12)])
    obj2cam = make_transform(np.eye(3), [5.0, -3.0, 350.0])
    cov = shared_shift_covariance(obj2cam, points, LENS, bias_px=0.1)
    assert np.sqrt(cov[0, 0]) == pytest.approx(0.1 * 350.0 / LENS.fu, rel=0.03)
    assert np.sqrt(cov[1, 1]) == pytest.approx(0.1 * 350.0 / LENS.fv, rel=0.03)
    assert np.sqrt(cov[2, 2]) < 0.1 * np.sqrt(cov[0, 0])  # no depth from a common shift
    assert np.allclose(cov, cov.T) and np.all(np.linalg.eigvalsh(cov) > -1e-12)
    assert np.allclose(shared_shift_covariance(obj2cam, points, LENS, bias_px=0.2), 4 * cov, rtol=1e-3)
    assert not shared_shift_covariance(obj2cam, points[:3], LENS).any()  # too few points to say
