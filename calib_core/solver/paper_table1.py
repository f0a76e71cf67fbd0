"""The paper's Table 1: Newton's method from ten displaced starts, with three fixture points.

The paper simulated the camera at a known location, projected three points of a grappling
fixture with its own equations, displaced the starting camera by the amounts below and let
Newton's method recover the location. Its final errors (1e-5 to 1e-7) are a stopping
tolerance; in double precision every start converges to round-off.

Displacements are applied as the solver parametrises the pose: ``t <- t + d`` (mm, camera
axes; for the paper's model, ``d_x``/``d_y`` shift its image-offset parameters by that
many units, as its table labels them) and ``R <- R(phi) R`` (deg, about the camera axes).
Errors are reported the same way: final minus true translation, and the rotation vector of
``R_final R_true^T`` in degrees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from calib_core.solver.kernels.newton import ROTATION_TOL_RAD
from calib_core.solver.paper_model import paper_shift_from_pose
from calib_core.solver.problem import make_problem
from calib_core.solver.refine import run_newton
from calib_core.solver.kernels.camera_models import PAPER, PINHOLE, evaluate
from scipy.spatial.transform import Rotation

# (d_x mm, d_y mm, d_z mm, phi_x deg, phi_y deg, phi_z deg): the paper's initial displacements.
PAPER_STARTS = (
    (10, 0, 0, 0, 0, 0),
    (0, 10, 0, 0, 0, 0),
    (0, 0, 10, 0, 0, 0),
    (10, 10, 10, 0, 0, 0),
    (0, 0, 0, 15, 0, 0),
    (0, 0, 0, 0, 15, 0),
    (0, 0, 0, 0, 0, 15),
    (0, 0, 0, 5, 10, 15),
    (10, 10, 10, 5, 10, 15),
    (100, 100, 100, 5, 10, 15),
)
# The paper's final errors for the same starts, in the same units.
PAPER_FINAL_ERRORS = (
    (-1.87e-5, 5.85e-7, 6.99e-6, 1.0e-7, 1.0e-7, -2.0e-6),
    (-1.85e-5, -6.69e-7, 7.38e-6, 1.0e-7, 1.0e-6, 1.0e-7),
    (-1.25e-5, 3.71e-7, 4.10e-6, 2.0e-6, 1.0e-7, -4.0e-6),
    (-4.90e-6, -1.78e-7, 1.53e-6, 1.0e-7, 1.0e-6, 1.0e-7),
    (3.92e-6, -2.93e-7, -1.06e-6, 1.0e-7, 1.0e-7, -1.0e-6),
    (1.84e-5, -4.99e-7, -1.72e-6, -1.0e-6, 1.0e-6, 1.0e-7),
    (-1.94e-5, 5.63e-6, 7.13e-6, 1.0e-7, 1.0e-6, -1.0e-6),
    (1.43e-6, -3.36e-7, -3.86e-7, -5.0e-6, -5.0e-6, -5.0e-6),
    (-5.51e-6, 1.34e-6, 6.79e-7, -3.0e-6, 2.0e-6, 3.0e-6),
    (-9.95e-5, -1.94e-5, -3.89e-5, -2.3e-5, 7.0e-6, 1.6e-5),
)

# The simulated scene: three points of a grappling fixture (mm, fixture frame) seen by the
# gripper camera (no lens distortion, as in the paper) from about half a metre.
FIXTURE_POINTS_MM = np.array([[-40.0, -30.0, 0.0], [45.0, -25.0, 10.0], [-5.0, 40.0, 25.0]])
CAMERA = Intrinsics(fu=1120.0, fv=1116.0, cx=645.2, cy=476.8, width=1280, height=960)
TRUE_OBJ2CAM = make_transform(
    Rotation.from_euler("xyz", [8.0, -12.0, 5.0], degrees=True).as_matrix(), [15.0, -10.0, 480.0]
)


@dataclass(frozen=True)
class Table1Row:
    """One test: ``start`` the initial displacement and ``final_error`` the error at the end,
    each ``(d_x, d_y, d_z, phi_x deg, phi_y deg, phi_z deg)``; ``paper`` the paper's figures."""

    test: int
    start: tuple[float, ...]
    final_error: tuple[float, ...]
    iterations: int
    converged: bool
    outcome: str
    paper: tuple[float, ...]

    @property
    def max_translation_error(self) -> float:
        return float(np.max(np.abs(self.final_error[:3])))

    @property
    def max_rotation_error_deg(self) -> float:
        return float(np.max(np.abs(self.final_error[3:])))


def _true_pixels(model: str) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (3, 2) of the fixture points at the true pose, and the true translation-like
    parameters (mm for the pinhole model, the paper's ``(d_x, d_y, d_z)`` for its model)."""
    R, t = TRUE_OBJ2CAM[:3, :3], TRUE_OBJ2CAM[:3, 3]
    P = FIXTURE_POINTS_MM
    r = np.empty((3, 2))
    J = np.empty((3, 2, 6))
    zeros = np.zeros((3, 2))
    if model == "paper":
        d = paper_shift_from_pose(t, CAMERA, CAMERA.fu, CAMERA.fv)
        evaluate(PAPER, P, zeros, R, d, CAMERA.fu, CAMERA.fv, CAMERA.cx, CAMERA.cy, np.zeros(5), False, False, r, J)
        return -r, d
    evaluate(PINHOLE, P, zeros, R, t, CAMERA.fu, CAMERA.fv, CAMERA.cx, CAMERA.cy, np.zeros(5), False, False, r, J)
    return -r, t.copy()


def run_table1(model: str = "pinhole", *, as_printed: bool = False) -> list[Table1Row]:
    """Run the ten tests. ``model``: ``"pinhole"`` or ``"paper"``; ``as_printed`` uses the
    paper's derivatives with their misprints and undamped Newton steps, as the paper would have."""
    pixels, t_true = _true_pixels(model)
    problem = make_problem(FIXTURE_POINTS_MM, pixels, CAMERA, model=model)
    R_true = TRUE_OBJ2CAM[:3, :3]
    rows = []
    for k, (start, paper) in enumerate(zip(PAPER_STARTS, PAPER_FINAL_ERRORS), start=1):
        d = np.asarray(start[:3], dtype=float)
        R0 = Rotation.from_rotvec(np.radians(start[3:])).as_matrix() @ R_true
        result = run_newton(
            problem,
            R0,
            t_true + d,
            CAMERA.fu,
            CAMERA.fv,
            damped=not as_printed,
            as_printed=as_printed,
            max_iterations=100,
        )
        rot_err = Rotation.from_matrix(result.R @ R_true.T).as_rotvec(degrees=True)
        err = tuple(float(x) for x in np.concatenate([result.t - t_true, rot_err]))
        rows.append(
            Table1Row(k, tuple(float(x) for x in start), err, result.iterations, result.converged, result.reason, paper)
        )
    return rows


__all__ = ["run_table1", "Table1Row", "PAPER_STARTS", "PAPER_FINAL_ERRORS", "ROTATION_TOL_RAD"]
