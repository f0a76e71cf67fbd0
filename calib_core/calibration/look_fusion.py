"""A look at a task location weighed against the calibrated model it corrects.

After a robot calibration the model itself places the TCP to a tenth of a millimetre, with a
covariance (:meth:`~calib_core.robot_calibration.calibrated_robot.RobotCalibration.pose_covariance`). A look measures
the TCP's displacement from that model with its own covariance. Applying the look whole throws the
model's knowledge away: a look noisier than the model makes the TCP worse (0.00026 -> 0.048 deg on
the cold cell). The two are fused as two measurements of one displacement: the model says zero with
its covariance, the look says what it saw with its own, and the result is their inverse-covariance
weighted mean (a Kalman update). When they disagree by more than both covariances allow, the look is
not used and the reason is given: a mis-detection must never move the robot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.special import chdtri

from calib_core.calibration.end_effector import EndEffectorEstimate
from calib_core.frames import concat, invert, make_transform

AGREEMENT = 0.9973
"""The look and the model agree when their difference lies within this share of both covariances
(chi-square, 6 degrees of freedom: 3 sigma)."""


@dataclass(frozen=True)
class FusedCorrection:
    """``displacement_mm`` (3,) and ``rotation_deg`` (3,) of the TCP (base frame, as
    :class:`EndEffectorEstimate`'s) with ``covariance`` (6, 6) in mm and deg; ``look_weight`` the
    share of the look in the result (0: the model alone, 1: the look alone), per axis; ``agree``
    whether the look was consistent with the model (``mahalanobis`` its squared distance);
    ``delta_base`` the correction to apply (``tcp_real = Δ @ tcp_model``)."""

    displacement_mm: np.ndarray
    rotation_deg: np.ndarray
    covariance: np.ndarray
    look_weight: np.ndarray
    mahalanobis: float
    agree: bool
    delta_base: np.ndarray
    message: str


def tcp_covariance_from_camera(camera_cov: np.ndarray, cam2base: np.ndarray, tcp2cam: np.ndarray) -> np.ndarray:
    """The TCP's covariance (6, 6: mm, deg) from its camera's (6, 6: mm, mrad, base frame), the TCP
    held rigidly at ``tcp2cam`` (4, 4) mm: a turn of the camera swings the TCP by the lever arm."""
    r = cam2base[:3, :3] @ tcp2cam[:3, 3]
    lever = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    A = np.zeros((6, 6))
    A[:3, :3] = np.eye(3)
    A[:3, 3:] = -lever / 1000.0
    A[3:, 3:] = np.eye(3) * np.degrees(1.0) / 1000.0  # mrad -> deg
    return A @ camera_cov @ A.T


def fuse_look(
    look: EndEffectorEstimate, model_covariance: np.ndarray, placement_sigma_mm: float = 0.0
) -> FusedCorrection:
    """The look's displacement fused with the model's prior (zero, ``model_covariance`` (6, 6) mm
    and deg of the TCP at the look's joints). The look sees the component where it stands, the model
    aims where the workcell file places it: ``placement_sigma_mm`` (1-sigma per axis, the survey's)
    widens the model's prior in position by that much. Raises ``ValueError`` for a look without
    covariance."""
    if look.covariance is None or not np.all(np.isfinite(look.covariance)):
        raise ValueError("the look has no covariance: it cannot be weighed against the model")
    x = np.r_[look.displacement_mm, look.rotation_deg]
    C_look = np.asarray(look.covariance, dtype=float)
    C_model = np.asarray(model_covariance, dtype=float) + np.diag([placement_sigma_mm**2] * 3 + [0.0] * 3)
    S = C_model + C_look
    m2 = float(x @ np.linalg.solve(S, x))
    agree = m2 <= chdtri(6, 1.0 - AGREEMENT)  # chi-square's AGREEMENT quantile, 6 dof
    if agree:
        K = C_model @ np.linalg.inv(S)
        fused, cov = K @ x, C_model - K @ C_model
        weight = np.clip(np.diag(K), 0.0, 1.0)
        message = (
            f"look and model agree (squared distance {m2:.1f}); the look weighs "
            f"{100 * float(np.mean(weight[:3])):.0f} % in position, {100 * float(np.mean(weight[3:])):.0f} % in "
            "rotation"
        )
    else:
        fused, cov, weight = np.zeros(6), C_model, np.zeros(6)
        message = (
            f"the look is {np.sqrt(m2):.1f} sigma from the calibrated model (its displacement "
            f"{np.linalg.norm(x[:3]):.3f} mm, "
            f"{np.linalg.norm(x[3:]):.4f} deg): not used; look again or pick the points by hand"
        )
    tcp = look.tcp2base_model
    R = Rotation.from_rotvec(np.radians(fused[3:])).as_matrix() @ tcp[:3, :3]
    delta = concat(invert(tcp), make_transform(R, tcp[:3, 3] + fused[:3]))
    return FusedCorrection(fused[:3], fused[3:], cov, weight, m2, bool(agree), delta, message)
