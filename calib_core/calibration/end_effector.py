"""From a solved camera pose to the real end-effector location and its displacement from the model.

The camera sees the target object; with the object's surveyed placement that gives the real
camera pose, and the camera is rigidly mounted on the gripper (``cam2flange``), so the real
tool centre point follows. Its difference from the modelled TCP at the same joints is what
the calibration stores. Uncertainty is carried from the pose covariance by a numerical Jacobian.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.frames import concat, invert, make_transform, pose_difference
from calib_core.solver.solution import PoseSolution
from calib_core.vision.pnp_sensitivity import pose_derivatives


@dataclass(frozen=True)
class EndEffectorEstimate:
    """``tcp2base_measured`` and ``tcp2base_model`` (4, 4) mm; ``displacement_mm`` (3,) the real
    TCP minus the modelled one (base frame), ``rotation_deg`` (3,) the rotation vector of
    ``R_real R_model^T`` (base frame); ``std_*`` their 1-sigma; ``cam2world_measured`` and
    ``cam2world_model`` the camera poses."""

    solution: PoseSolution
    obj2world: np.ndarray
    cam2world_model: np.ndarray
    cam2world_measured: np.ndarray
    tcp2base_model: np.ndarray
    tcp2base_measured: np.ndarray
    displacement_mm: np.ndarray
    rotation_deg: np.ndarray
    std_displacement_mm: np.ndarray
    std_rotation_deg: np.ndarray
    covariance: np.ndarray | None = None
    """(6, 6) of (displacement mm, rotation deg); ``None`` when the solve gave no uncertainty."""

    @property
    def delta_base(self) -> np.ndarray:
        """``Δ`` (4, 4) with ``tcp_real = Δ @ tcp_model`` in the base frame."""
        return concat(invert(self.tcp2base_model), self.tcp2base_measured)


SHARED_BIAS_PX = 0.1
"""An error every image point of one look shares (1-sigma per image axis, px): the sub-pixel
refinement under the frame's own lighting, or a principal point known to a tenth of a pixel. The
residuals cannot show it (a common shift is a turn of the camera, and the pose absorbs it), so the
look's covariance carries it. Measured on the simulated cell: refined corners 0.06-0.14 px off the
truth the same way in one frame; without it one look at the task location was 3.3-4.4 sigma off
along the image's vertical."""


def shared_shift_covariance(
    obj2cam: np.ndarray, points_obj_mm: np.ndarray, intrinsics, bias_px: float = SHARED_BIAS_PX, step_px: float = 0.5
) -> np.ndarray:
    """(6, 6) covariance, in the solver's (dt mm, phi rad) on ``obj2cam`` (4, 4), of every image
    point of ``points_obj_mm`` (m, 3, the object's frame) shifted by the same ``bias_px`` (1-sigma per
    image axis): how the pose that puts the points on the shifted pixels moves, by central
    differences of OpenCV's PnP refinement from ``obj2cam`` (a common shift is a principal point
    moved the other way). Zeros when fewer than 4 points."""
    pts = np.asarray(points_obj_mm, dtype=np.float64).reshape(-1, 3)
    if len(pts) < 4 or bias_px <= 0:
        return np.zeros((6, 6))

    def shift(axis):
        def change(d, pixels):
            pixels[:, axis] += d
            return pixels, intrinsics

        return change

    def difference(start, moved):  # the solver's (dt mm, phi rad)
        return np.r_[moved[:3, 3] - start[:3, 3], Rotation.from_matrix(moved[:3, :3] @ start[:3, :3].T).as_rotvec()]

    S = pose_derivatives(obj2cam, pts, intrinsics, [shift(0), shift(1)], difference, step_px)
    return bias_px**2 * S @ S.T


def _measured_tcp(obj2cam: np.ndarray, obj2world: np.ndarray, tcp2cam: np.ndarray) -> np.ndarray:
    cam2world = concat(invert(obj2cam), obj2world)
    return concat(tcp2cam, cam2world)


def end_effector_from_solution(
    solution: PoseSolution,
    obj2world: np.ndarray,
    cam2world_model: np.ndarray,
    tcp2base_model: np.ndarray,
    obj2cam: np.ndarray | None = None,
    shared_covariance: np.ndarray | None = None,
) -> EndEffectorEstimate:
    """The real TCP from a solve (or from candidate ``obj2cam`` when given); its covariance is the
    solve's plus ``shared_covariance`` (6, 6, the solver's units: the image points' shared error,
    :func:`shared_shift_covariance`)."""
    obj2cam = solution.obj2cam if obj2cam is None else obj2cam
    tcp2cam = concat(tcp2base_model, invert(cam2world_model))
    tcp_meas = _measured_tcp(obj2cam, obj2world, tcp2cam)
    d, rv = pose_difference(tcp_meas, tcp2base_model)
    std_d = np.full(3, np.nan)
    std_r = np.full(3, np.nan)
    cov = None
    u = solution.uncertainty
    if u is not None and np.all(np.isfinite(u.covariance[:6, :6])):
        # Jacobian of (d, rotvec) with respect to the solver's (dt mm, phi rad) on obj2cam.
        J = np.zeros((6, 6))
        h = np.array([1e-4, 1e-4, 1e-4, 1e-7, 1e-7, 1e-7])
        for k in range(6):
            out = []
            for sign in (1.0, -1.0):
                step = np.zeros(6)
                step[k] = sign * h[k]
                R = Rotation.from_rotvec(step[3:]).as_matrix() @ obj2cam[:3, :3]
                perturbed = make_transform(R, obj2cam[:3, 3] + step[:3])
                dd, rr = pose_difference(_measured_tcp(perturbed, obj2world, tcp2cam), tcp2base_model)
                out.append(np.concatenate([dd, rr]))
            J[:, k] = (out[0] - out[1]) / (2 * h[k])
        pose_cov = u.covariance[:6, :6] if shared_covariance is None else u.covariance[:6, :6] + shared_covariance
        cov = J @ pose_cov @ J.T
        std = np.sqrt(np.clip(np.diag(cov), 0, None))
        std_d, std_r = std[:3], std[3:]
    return EndEffectorEstimate(
        solution,
        obj2world,
        cam2world_model,
        concat(invert(obj2cam), obj2world),
        tcp2base_model,
        tcp_meas,
        d,
        rv,
        std_d,
        std_r,
        cov,
    )
