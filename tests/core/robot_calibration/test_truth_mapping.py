"""The test bed's truth written in the error model's own parameters: the scoring's basis (known answer:
the model with those parameters moves exactly like the true robot)."""

import numpy as np

from calib_core.frames import pose_difference
from calib_core.robot_calibration.parameters import CorrectedRobot
from videocal_sim.cold_cell import cold_test_bed
from videocal_sim.cold_robot_calibration import truth_in_model_parameters


def test_the_truth_in_model_parameters_moves_like_the_true_robot():
    bed, _ = cold_test_bed(seed=1)
    p = truth_in_model_parameters(bed)
    assert np.abs(p).max() > 0.1  # the cold robot is really off
    model = CorrectedRobot(bed.model_robot)
    model.set(p)
    rng = np.random.default_rng(0)
    for _ in range(10):
        q = rng.uniform(-120, 120, 6)
        for frame in ("camera", "flange", "tcp"):
            d, r = pose_difference(model.robot.fk(q, frame), bed.true_robot.fk(q, frame))
            assert np.linalg.norm(d) < 1e-9 and np.linalg.norm(r) < 1e-10
