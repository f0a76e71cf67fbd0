"""Where the object is believed to be before the image is read, as one more measurement of a pose fit.

A look starts from where the robot's model puts the object, good to the robot's error (the reach: mm and deg). A fit
on the image alone may walk along a direction the image hardly fixes (the depth of a small object a metre away: a
few pixels of outline trade for 30-100 mm) onto a neighbour's edges. Taken as a measurement of the object's position
and turn with that 1-sigma, the prior keeps such a fit near, and the image still moves it wherever it says more.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.frames import rotation_angle_deg


@dataclass(frozen=True)
class PosePrior:
    """``obj2cam`` (4, 4, mm) with its 1-sigma: ``sigma_mm`` of the object's position, ``sigma_deg`` of its turn (each
    per axis, camera frame)."""

    obj2cam: np.ndarray
    sigma_mm: float
    sigma_deg: float

    def __post_init__(self) -> None:
        from calib_core.errors import OperatorError

        for name, value, unit in (("reach", self.sigma_mm, "mm"), ("reach", self.sigma_deg, "deg")):
            if not (np.isfinite(value) and value > 0.0):
                raise OperatorError(
                    f"the look's {name} must be above 0 {unit} (how far the object may lie from the prior), got "
                    f"{value!r}"
                )

    def normal_equations(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The prior's terms (6, 6) and (6,) to add to a Gauss-Newton step's ``J^T W J`` and ``J^T W r`` at ``pose``
        (4, 4, mm), in the step's six small motions (the rotation vector rad, then the translation mm, both in the
        camera frame, the rotation turning the translation too: ``t' = R(w) t + v``), in units of a residual of 1. The
        turn's derivative is taken as the identity (first order in the turn from the prior, a few degrees: 1 % at 2
        deg); the steps still end exactly at what the residuals say."""
        turn = Rotation.from_matrix(pose[:3, :3] @ self.obj2cam[:3, :3].T).as_rotvec()
        moved = pose[:3, 3] - self.obj2cam[:3, 3]
        t = pose[:3, 3]
        J = np.zeros((6, 6))
        J[:3, :3] = np.eye(3)
        J[3:, :3] = -np.array([[0.0, -t[2], t[1]], [t[2], 0.0, -t[0]], [-t[1], t[0], 0.0]])  # d(R(w) t)/dw = -[t]x
        J[3:, 3:] = np.eye(3)
        W = np.diag([1.0 / np.radians(self.sigma_deg) ** 2] * 3 + [1.0 / self.sigma_mm**2] * 3)
        return J.T @ W @ J, J.T @ W @ -np.concatenate([turn, moved])

    def holds(self, pose: np.ndarray, sigmas: float = 3.0) -> bool:
        """Whether ``pose`` (4, 4, mm) lies within ``sigmas`` times the prior's 1-sigma both in position (the distance
        between the two positions, mm) and in turn (the angle between the two orientations, deg): how far a look's
        search covered round the prior."""
        moved = float(np.linalg.norm(pose[:3, 3] - self.obj2cam[:3, 3]))
        turned = rotation_angle_deg(pose[:3, :3] @ self.obj2cam[:3, :3].T)
        return moved <= sigmas * self.sigma_mm and turned <= sigmas * self.sigma_deg
