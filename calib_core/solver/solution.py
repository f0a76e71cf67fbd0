"""The result of a pose solve: status, pose, focal lengths, uncertainty and diagnostics."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from typing import TYPE_CHECKING

from calib_core.frames import invert, make_transform

if TYPE_CHECKING:  # the uncertainty module imports the compiled kernels: not needed to read a result
    from calib_core.solver.uncertainty import PoseUncertainty


class SolveStatus(str, Enum):
    """``ok``: one pose fits well. ``ambiguous``: several poses fit about equally well (see
    ``candidates``). ``failed``: no pose fits; ``reason`` says why in words."""

    OK = "ok"
    AMBIGUOUS = "ambiguous"
    FAILED = "failed"


@dataclass(frozen=True)
class PoseCandidate:
    """One refined pose that explains the picks. ``obj2cam`` (4, 4), mm; ``rms_px`` its
    reprojection RMS; ``distance_to_prior_mm`` how far it is from the modelled camera pose
    (translation plus rotation as arc length at the object distance), ``None`` without a prior."""

    obj2cam: np.ndarray
    fu: float
    fv: float
    rms_px: float
    distance_to_prior_mm: float | None = None

    def to_dict(self) -> dict:
        return {
            "R_obj2cam": self.obj2cam[:3, :3].tolist(),
            "t_obj2cam_mm": self.obj2cam[:3, 3].tolist(),
            "rms_px": self.rms_px,
            "fu": self.fu,
            "fv": self.fv,
            "distance_to_prior_mm": self.distance_to_prior_mm,
        }


@dataclass(frozen=True)
class PoseSolution:
    """Everything a solve found.

    ``obj2cam`` (4, 4) maps object-frame mm to camera-frame mm (OpenCV axes: x right,
    y down, z forward). ``residuals_px`` (n, 2) are ``observed - reprojected``;
    ``leave_one_out_px`` (n,) how far each point would miss if solved without it;
    ``outliers`` (n,) the points the robust loss rejected. ``candidates`` are all poses
    that fit about as well as the chosen one, best first (the chosen one included).
    """

    status: SolveStatus
    obj2cam: np.ndarray
    fu: float
    fv: float
    model: str
    iterations: int
    residuals_px: np.ndarray
    uncertainty: PoseUncertainty | None
    leave_one_out_px: np.ndarray
    outliers: np.ndarray
    candidates: tuple[PoseCandidate, ...] = ()
    reason: str | None = None
    warnings: tuple[str, ...] = field(default_factory=tuple)
    method: str = "points"
    """``points``: solved from point pairs; ``edges``: from the target's edges on the image (the
    residuals are then the edge samples' offsets, one per sample)."""
    misfits: np.ndarray | None = None
    """(n,) bool: the pairs the leave-one-out test says do not fit the others (likely mis-picks), or None."""

    @property
    def ok(self) -> bool:
        return self.status is SolveStatus.OK

    @property
    def R_obj2cam(self) -> np.ndarray:
        return self.obj2cam[:3, :3]

    @property
    def t_obj2cam_mm(self) -> np.ndarray:
        return self.obj2cam[:3, 3]

    @property
    def cam2obj(self) -> np.ndarray:
        return invert(self.obj2cam)

    @property
    def camera_position_mm(self) -> np.ndarray:
        """The camera centre in the object frame, mm (3,)."""
        return -self.R_obj2cam.T @ self.t_obj2cam_mm

    @property
    def residual_norms_px(self) -> np.ndarray:
        return np.linalg.norm(self.residuals_px, axis=1)

    @property
    def rms_px(self) -> float:
        """RMS of the residual lengths over the points not flagged as outliers, px."""
        keep = ~self.outliers
        e = self.residual_norms_px[keep]
        return float(np.sqrt(np.mean(e**2))) if len(e) else float("nan")

    def to_dict(self) -> dict:
        """A JSON-ready dict with the field names of ``videocal solve``."""
        u = self.uncertainty

        def finite(values) -> list:
            return [None if not np.isfinite(v) else float(v) for v in np.ravel(values)]

        return {
            "status": self.status.value,
            "reason": self.reason,
            "model": self.model,
            "R_obj2cam": self.R_obj2cam.tolist(),
            "t_obj2cam_mm": self.t_obj2cam_mm.tolist(),
            "camera_position_mm": self.camera_position_mm.tolist(),
            "fu": self.fu,
            "fv": self.fv,
            "iterations": self.iterations,
            "rms_px": self.rms_px,
            "residuals_px": self.residuals_px.tolist(),
            "leave_one_out_px": finite(self.leave_one_out_px),
            "outliers": [bool(x) for x in self.outliers],
            "misfits": [bool(x) for x in self.misfits] if self.misfits is not None else None,
            "std": None
            if u is None
            else {
                "t_obj2cam_mm": finite(u.std_t_obj2cam_mm),
                "rotation_deg": finite(u.std_rotation_deg),
                "camera_position_mm": finite(u.std_camera_position_mm),
                "fu": u.std_fu_px,
                "fv": u.std_fv_px,
                "sigma_px": u.sigma_px,
                "sigma_source": u.sigma_source,
            },
            "condition_number": None if u is None or not np.isfinite(u.condition_number) else u.condition_number,
            "candidates": [c.to_dict() for c in self.candidates],
            "warnings": list(self.warnings),
            "method": self.method,
        }


def pose_matrix(R: np.ndarray, t_mm: np.ndarray) -> np.ndarray:
    """``obj2cam`` (4, 4) from ``R`` (3, 3) and ``t`` (3,) mm."""
    return make_transform(R, t_mm)
