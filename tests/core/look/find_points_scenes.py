"""The bundled cell's fixture as a look's target: robot errors scaled, and how far found points lie from the truth."""

from __future__ import annotations

import numpy as np

from calib_core.camera.projection import project_points
from videocal_sim.true_robot import RobotErrors

TARGET = "oru_1_fixture"


def errors_times(factor: float) -> RobotErrors:
    e = RobotErrors.typical(0, n_joints=6)
    return RobotErrors(
        e.joint_offsets_deg * factor,
        e.link_errors_mm * factor,
        e.base_xyz_mm * factor,
        e.base_rpy_deg * factor,
        e.hand_eye_xyz_mm * factor,
        e.hand_eye_rpy_deg * factor,
    )


def pixel_errors(item, pose, truth, intrinsics):
    points = np.array(list(item.features.values()))
    return np.linalg.norm(project_points(points, pose, intrinsics) - project_points(points, truth, intrinsics), axis=1)
