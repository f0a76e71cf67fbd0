"""What a robot's identification gives: its parameters with their 1-sigma and covariance, the calibrated model, how
well it fits, and what it says of a pose the robot takes (:meth:`RobotCalibration.pose_covariance`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.observability import Observability
from calib_core.robot_calibration.parameters import CorrectedRobot

FD_STEP = 1e-4
"""Forward-difference step, in parameter units (mm, mrad, px, thousandths)."""


@dataclass(frozen=True)
class RobotCalibration:
    """``names`` of the parameters, ``values`` (p,) and 1-sigma ``sigmas`` (p,) in their units
    (NaN sigma: not identified, left at 0); ``observability``; ``board2base`` (4, 4) mm or ``None``;
    ``rms_px`` over all points and ``per_view_rms_px``; ``noise_px`` the residuals' sigma per
    coordinate; ``robot`` the calibrated model and ``intrinsics`` the camera (calibrated when asked)."""

    names: list[str]
    values: np.ndarray
    sigmas: np.ndarray
    observability: Observability
    board2base: np.ndarray | None
    rms_px: float
    per_view_rms_px: dict[str, float]
    noise_px: float
    robot: RobotModel
    intrinsics: Intrinsics
    seconds: float
    start_rms_px: float
    warnings: list[str] = field(default_factory=list)
    covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """(k, k) of the identified parameters, in the order of ``observability.identified``."""
    nominal: RobotModel | None = None
    """A copy of the robot the identification started from (applying the result changes the robot)."""
    camera_frame: str = "camera"
    residual_weights: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """The weight of every residual in the final fit (1 / its group's sigma)."""
    noise_by_target_px: dict[str, float] = field(default_factory=dict)
    """The residuals' sigma (px per coordinate) of the board views and of the surveyed-feature views,
    each group weighted by its own."""
    left_out: dict[str, str] = field(default_factory=dict)
    """Views given no weight in the final fit (view name -> why): a component's pose that disagrees
    with the rest (an edge fit settled on the wrong edges)."""

    def parameter(self, name: str) -> tuple[float, float]:
        k = self.names.index(name)
        return float(self.values[k]), float(self.sigmas[k])

    @property
    def identified_names(self) -> list[str]:
        return [self.names[k] for k in self.observability.identified]

    def pose_covariance(self, q_deg, frame: str = "camera") -> np.ndarray:
        """The covariance (6, 6) of ``frame``'s pose at joints ``q_deg`` from the identified parameters'
        covariance: translation (mm) then rotation vector (mrad), both in the base frame."""
        corrected = CorrectedRobot(self.nominal, self.camera_frame, len(self.values) > 6 * (self.nominal.n_joints + 1))
        corrected.set(self.values)
        T0 = corrected.robot.fk(q_deg, frame)
        ids = self.observability.identified
        J = np.empty((6, len(ids)))
        for c, k in enumerate(ids):
            p = self.values.copy()
            p[k] += FD_STEP
            corrected.set(p)
            T = corrected.robot.fk(q_deg, frame)
            J[:3, c] = (T[:3, 3] - T0[:3, 3]) / FD_STEP
            J[3:, c] = 1000.0 * Rotation.from_matrix(T[:3, :3] @ T0[:3, :3].T).as_rotvec() / FD_STEP
        return J @ self.covariance @ J.T
