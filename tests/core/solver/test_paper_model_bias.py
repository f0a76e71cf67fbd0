"""The paper's model fits three points exactly, yet its pose is biased off the optical axis."""

import numpy as np

from calib_core.frames import make_transform
from calib_core.solver import solve_pose

from tests.core.solver.scenes import PINHOLE_CAMERA, pixels, pose_error

FIXTURE = np.array([[-30.0, -20.0, 0.0], [35.0, -15.0, 5.0], [0.0, 30.0, 15.0]])


def _solve_both(offset_mm):
    truth = make_transform(np.eye(3), [offset_mm, 0.0, 500.0])
    uv = pixels(FIXTURE, truth, PINHOLE_CAMERA)
    prior = make_transform(np.eye(3), [offset_mm, 0.0, 500.0])
    paper = solve_pose(FIXTURE, uv, PINHOLE_CAMERA, model="paper", prior=prior)
    pinhole = solve_pose(FIXTURE, uv, PINHOLE_CAMERA, prior=prior)
    return truth, paper, pinhole


def test_on_axis_both_models_agree():
    truth, paper, pinhole = _solve_both(0.0)
    assert pose_error(pinhole.obj2cam, truth)[0] < 1e-6
    assert pose_error(paper.obj2cam, truth)[0] < 0.5  # exact only for the object origin itself


def test_off_axis_the_paper_model_is_biased_with_zero_residual():
    truth, paper, pinhole = _solve_both(100.0)
    assert paper.rms_px < 1e-6  # the fit looks perfect...
    dt, dr = pose_error(paper.obj2cam, truth)
    assert dt > 20.0 or dr > 2.0  # ...yet the pose is far off
    assert pose_error(pinhole.obj2cam, truth)[0] < 1e-6
