"""Covariance of a solved pose from the Jacobian at the optimum, and leave-one-out residuals.

Parameters are ordered as in the solver: ``dt_x, dt_y, dt_z`` (mm, camera frame),
``phi_x, phi_y, phi_z`` (rad, about the camera axes) and optionally ``fu, fv`` (px).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.solver.kernels.diagnostics import fit_summary

DEFAULT_SIGMA_PX = 0.5


@dataclass(frozen=True)
class PoseUncertainty:
    """1-sigma uncertainty of a pose.

    ``covariance`` (p, p) in solver units; ``std_t_obj2cam_mm`` (3,), ``std_rotation_deg``
    (3,) about the camera axes, ``std_camera_position_mm`` (3,) in the object frame,
    ``std_fu_px``/``std_fv_px`` (``None`` when not estimated). ``sigma_px`` is the image
    noise used and ``sigma_source`` where it came from: ``estimated`` from the residuals,
    ``given`` by the caller, or ``default`` (no redundancy to estimate it from).
    """

    covariance: np.ndarray
    std_t_obj2cam_mm: np.ndarray
    std_rotation_deg: np.ndarray
    std_camera_position_mm: np.ndarray
    std_fu_px: float | None
    std_fv_px: float | None
    sigma_px: float
    sigma_source: str
    condition_number: float


_SOURCES = ("given", "estimated", "default")


def fit_uncertainty(
    jacobian: np.ndarray,
    residuals: np.ndarray,
    weights: np.ndarray,
    R_obj2cam: np.ndarray,
    t_obj2cam_mm: np.ndarray,
    sigma_px: float | None,
    to_metric: np.ndarray | None = None,
) -> tuple[float, np.ndarray, np.ndarray, PoseUncertainty]:
    """Covariance ``sigma^2 (J^T W J)^-1`` and the figures derived from it.

    ``jacobian`` (n, 2, p) of the predicted pixels, ``residuals`` (n, 2) px, ``weights``
    (n,) per point (0 drops it); ``sigma_px`` the pick noise, estimated from the residuals
    when ``None`` and there is redundancy, else :data:`DEFAULT_SIGMA_PX`. ``to_metric``
    (p, p): the derivative of the metric parameters with respect to the model's own (the
    paper's model solves image shifts, not mm).

    Returns ``(rms_px, residual lengths (n,) px, leave-one-out residuals (n,) px,
    uncertainty)``. Leave-one-out: how far each point would land from its pick if the pose
    were solved without it (first order, from the hat matrix; NaN where dropping the point
    leaves no redundancy).
    """
    n, _, p = jacobian.shape
    cov = np.empty((p, p))
    cov_c = np.empty((3, 3))
    loo = np.empty(n)
    lengths = np.empty(n)
    rms, sigma, source, condition = fit_summary(
        jacobian,
        residuals,
        weights,
        R_obj2cam,
        t_obj2cam_mm,
        -1.0 if sigma_px is None else float(sigma_px),
        DEFAULT_SIGMA_PX,
        cov,
        cov_c,
        loo,
        lengths,
    )
    if to_metric is not None:
        # The paper's model solves image shifts: carry its covariance over to the metric pose.
        cov = to_metric @ cov @ to_metric.T
        cov_c = _centre_covariance(cov, R_obj2cam, t_obj2cam_mm)
    return float(rms), lengths, loo, uncertainty_from(cov, cov_c, sigma, int(source), condition)


def uncertainty_from(
    cov: np.ndarray, cov_centre: np.ndarray, sigma_px: float, source: int, condition: float
) -> PoseUncertainty:
    """Package a covariance (p, p) and the camera centre's (3, 3) as 1-sigma figures."""
    var = cov.diagonal()
    std = np.sqrt(var)
    focal = len(var) == 8
    return PoseUncertainty(
        covariance=cov,
        std_t_obj2cam_mm=std[:3],
        std_rotation_deg=np.degrees(std[3:6]),
        std_camera_position_mm=np.sqrt(cov_centre.diagonal()),
        std_fu_px=float(std[6]) if focal else None,
        std_fv_px=float(std[7]) if focal else None,
        sigma_px=float(sigma_px),
        sigma_source=_SOURCES[source],
        condition_number=float(condition),
    )


def _centre_covariance(cov: np.ndarray, R_obj2cam: np.ndarray, t_obj2cam_mm: np.ndarray) -> np.ndarray:
    """Covariance (3, 3) of the camera centre ``c = -R^T t``: dc/dt = -R^T, dc/dphi = -R^T [t]x."""
    Rt = R_obj2cam.T
    tx, ty, tz = t_obj2cam_mm
    t_cross = np.array([[0.0, -tz, ty], [tz, 0.0, -tx], [-ty, tx, 0.0]])
    A = np.hstack([-Rt, -Rt @ t_cross])
    return A @ cov[:6, :6] @ A.T
