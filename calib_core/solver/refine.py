"""Refinement of one pose from a start, in either camera model, through the compiled Newton loop.

A state is ``(R, t, fu, fv)``: ``R`` (3, 3) the object-to-camera rotation, ``t`` (3,)
the object origin in the camera frame (mm) for the pinhole model, or the paper's
``(d_x px, d_y px, d_z mm)`` for the paper's model; ``fu``, ``fv`` focal lengths, px.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from calib_core.camera.projection import undistort_pixels
from calib_core.solver.kernels.camera_models import PAPER, PINHOLE, evaluate
from calib_core.solver.kernels.newton import CONVERGED, EXACT_FIT, OUTCOMES, newton
from calib_core.solver.problem import PoseProblem

_NO_DISTORTION = np.zeros(5)


@dataclass(frozen=True)
class NewtonResult:
    """Where the iterations stopped: the state, and ``residuals`` (n, 2) px (observed -
    predicted) and ``jacobian`` (n, 2, p) of the predicted pixels at that state."""

    R: np.ndarray
    t: np.ndarray
    fu: float
    fv: float
    residuals: np.ndarray
    jacobian: np.ndarray
    iterations: int
    outcome: int

    @property
    def converged(self) -> bool:
        return self.outcome in (CONVERGED, EXACT_FIT)

    @property
    def reason(self) -> str:
        return OUTCOMES[self.outcome]


def ideal_pixels(problem: PoseProblem) -> np.ndarray:
    """The observed pixels with lens distortion removed (n, 2), px: what the paper's model sees."""
    if not problem.intrinsics.has_distortion:
        return problem.points_2d
    return undistort_pixels(problem.points_2d, problem.intrinsics)


def _model_inputs(problem: PoseProblem, model: str) -> tuple[int, np.ndarray, np.ndarray]:
    if model == "paper":
        return PAPER, ideal_pixels(problem), _NO_DISTORTION
    return PINHOLE, problem.points_2d, problem.distortion


def run_newton(
    problem: PoseProblem,
    R,
    t,
    fu: float,
    fv: float,
    *,
    huber_px: float | None = None,
    max_iterations: int = 100,
    damped: bool = True,
    as_printed: bool = False,
) -> NewtonResult:
    """Iterate from ``(R, t, fu, fv)`` in the problem's model (``as_printed``: the paper's
    misprinted derivatives, with ``damped=False`` its undamped Newton steps)."""
    code, uv, dist = _model_inputs(problem, problem.model)
    R = np.array(R, dtype=float)
    t = np.array(t, dtype=float).reshape(3)
    f = np.array([fu, fv], dtype=float)
    n = problem.n_points
    r = np.empty((n, 2))
    J = np.empty((n, 2, problem.n_params))
    intr = problem.intrinsics
    iterations, outcome = newton(
        code,
        problem.points_3d,
        uv,
        R,
        t,
        f,
        intr.cx,
        intr.cy,
        dist,
        problem.estimate_focal,
        as_printed,
        huber_px or 0.0,
        max_iterations,
        damped,
        r,
        J,
    )
    return NewtonResult(R, t, float(f[0]), float(f[1]), r, J, int(iterations), int(outcome))


def residuals_and_jacobian(
    problem: PoseProblem, R, t, fu: float, fv: float, *, as_printed: bool = False
) -> tuple[np.ndarray, np.ndarray, float]:
    """Residuals (n, 2) px, Jacobian (n, 2, p) and the smallest depth (mm) at a state."""
    code, uv, dist = _model_inputs(problem, problem.model)
    n = problem.n_points
    r = np.empty((n, 2))
    J = np.empty((n, 2, problem.n_params))
    intr = problem.intrinsics
    zmin = evaluate(
        code,
        problem.points_3d,
        uv,
        np.asarray(R, dtype=float),
        np.asarray(t, dtype=float),
        float(fu),
        float(fv),
        intr.cx,
        intr.cy,
        dist,
        problem.estimate_focal,
        as_printed,
        r,
        J,
    )
    return r, J, float(zmin)
