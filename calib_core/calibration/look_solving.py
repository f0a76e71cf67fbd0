"""*Calibrate*: the session's pairs solved for the camera's pose, hence the end effector's, and a solve made the
session's result (one undoable command).

The solve is a service the session is given (``solve``: :func:`calib_core.solver.solve.solve_pose` unless a caller
names another); the session itself only holds the pairs, the options, the result and the corrections.
"""

from __future__ import annotations

import numpy as np

from calib_core.calibration.end_effector import EndEffectorEstimate, end_effector_from_solution
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.look_result import ShowSolved, SolveContext, Solved, pairs_key, shared_covariance
from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import apply, concat, invert
from calib_core.solver.solve_inputs import solve_inputs


def calibrate(
    session,
    intrinsics: Intrinsics,
    obj2world: np.ndarray,
    cam2world_model: np.ndarray,
    tcp2base_model: np.ndarray,
    joints_deg=None,
    *,
    form_tolerance_mm: float = 0.0,
    solve=None,
) -> EndEffectorEstimate:
    """``Calibrate``: solve the camera pose from ``session``'s usable pairs (in the target's frame, ``obj2world``
    (4, 4) mm) with the modelled camera pose ``cam2world_model`` as the prior, and the real end-effector location
    from it; its uncertainty carries the target's ``form_tolerance_mm`` (1-sigma of its features about their CAD
    positions). Refused (:class:`CalibrationError`) without a target or with too few complete pairs."""
    if session.target is None:
        raise CalibrationError("choose the target object first")
    use, needed = session.pairs.usable(), session.options.required_pairs
    if len(use) < needed:
        why = " (focal lengths are estimated)" if session.options.estimate_focal else ""
        raise CalibrationError(f"{len(use)} complete pairs; calibrating needs {needed}{why}")
    points_world, pixels, numbers = session.pairs.arrays()
    points_obj = apply(invert(obj2world), points_world)
    prior = concat(obj2world, invert(cam2world_model))
    from calib_core.solver.errors import named_points

    if solve is None:
        from calib_core.solver.solve import solve_pose as solve  # the solver's compiled kernels load on the first solve

    how = dict(prior=prior, estimate_focal=session.options.estimate_focal, robust=session.options.robust)
    with named_points("pair", numbers):  # messages name pairs by the numbers the table shows
        solution = solve(points_obj, pixels, intrinsics, **how)
    return show_solution(
        session,
        solution,
        obj2world,
        cam2world_model,
        tcp2base_model,
        joints_deg,
        numbers,
        points_obj_mm=points_obj,
        intrinsics=intrinsics,
        label=f"Calibrate ({len(numbers)} pairs)",
        form_tolerance_mm=form_tolerance_mm,
        inputs=solve_inputs(points_obj, pixels, intrinsics, **how),
    )


def show_solution(
    session,
    solution,
    obj2world: np.ndarray,
    cam2world_model: np.ndarray,
    tcp2base_model: np.ndarray,
    joints_deg,
    numbers: list[int],
    *,
    points_obj_mm=None,
    intrinsics: Intrinsics | None = None,
    view_sources: tuple[str, ...] | None = None,
    label: str | None = None,
    form_tolerance_mm: float = 0.0,
    inputs: dict | None = None,
) -> EndEffectorEstimate:
    """Make ``solution`` ``session``'s result. With a ``label`` it is an operator's solve: one
    command on the undo stack (undo brings the previous result back); without, a solve shown from
    elsewhere (a recording being replayed), which is not an edit. With the solve's
    ``points_obj_mm`` (m, 3, the target's frame) and ``intrinsics`` the result's covariance
    carries the image points' shared error
    (:func:`~calib_core.calibration.end_effector.shared_shift_covariance`) and the target's
    ``form_tolerance_mm`` (:func:`~calib_core.calibration.form_error.form_error_covariance`). ``view_sources``:
    the recordings the look's frames came from, by name (default: the used pairs' stamps; empty: all live).
    ``inputs``: the solve's inputs as a recording keeps them."""
    used = [p for p in session.pairs if p.number in set(numbers)]
    points = None if points_obj_mm is None else np.asarray(points_obj_mm, dtype=float).reshape(-1, 3)
    if view_sources is None:
        view_sources = tuple(sorted({p.view.source for p in used if p.view is not None and p.view.recorded}))
    context = SolveContext(
        obj2world,
        cam2world_model,
        tcp2base_model,
        None if joints_deg is None else np.asarray(joints_deg, float),
        tuple(numbers),
        pairs_key(used),
        points,
        intrinsics,
        tuple(view_sources),
        float(form_tolerance_mm),
    )
    estimate = end_effector_from_solution(
        solution,
        obj2world,
        cam2world_model,
        tcp2base_model,
        shared_covariance=shared_covariance(context, solution.obj2cam),
    )
    if inputs is not None:
        session.result.inputs = inputs
    solved = Solved(estimate, context, 0)
    if label is None:
        session.result.show(solved)
    else:
        session.undo.push(ShowSolved(session.result, solved, label))
    return estimate
