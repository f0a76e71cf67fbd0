"""A calibration session: the target object, the pairs, the solve's options, the result and the corrections, with
one undo stack for every edit of them.

This is the calibration mode of the paper's command window without the window: ``Target object``, ``Point`` (3D
then 2D), ``Accept``, ``Calibrate``, ``Store correction``. Each concept has its owner, which the views subscribe to:
``pairs`` (:class:`~calib_core.calibration.correspondences.CorrespondenceSet`), ``options``
(:class:`~calib_core.calibration.solve_options.SolveOptions`), ``result`` (the last solve and its verdict,
:class:`~calib_core.calibration.look_result.LookResult`), ``corrections``
(:class:`~calib_core.calibration.corrections.CorrectionTable`); the session relates them (a result belongs to the
pairs it was solved from) and puts their edits on ``undo``.
"""

from __future__ import annotations

import numpy as np
from psygnal import Signal

from calib_core.calibration.commands import AddPoint3D, ClearPairs, DeletePair, SetEnabled, SetPixel
from calib_core.calibration.correction_from_look import correction_from_look
from calib_core.calibration.corrections import Correction, CorrectionTable, StoreCorrection
from calib_core.calibration.correspondences import CorrespondenceSet
from calib_core.calibration.end_effector import EndEffectorEstimate, end_effector_from_solution
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.look_result import (
    ChooseCandidate,
    LookResult,
    ShowSolved,
    SolveContext,
    Solved,
    pairs_key,
    shared_covariance,
)
from calib_core.calibration.solve_options import SetOption, SolveOptions
from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import apply, concat, invert
from calib_core.solver.solution import SolveStatus
from calib_core.solver.solve_inputs import solve_inputs
from calib_core.undo import UndoStack


class CalibrationSession:
    """One calibration's state, each part its own owner. Event (psygnal): ``target_changed(name)``."""

    target_changed = Signal(object)

    def __init__(self) -> None:
        self.pairs = CorrespondenceSet()
        self.undo = UndoStack()
        self.corrections = CorrectionTable()
        self.options = SolveOptions()
        self.result = LookResult()
        self.target: str | None = None

    def set_option(self, name: str, value: bool) -> None:
        """Set a solve option through the undo stack (nothing happens when it already has ``value``)."""
        if getattr(self.options, self.options.check(name)) != bool(value):
            self.undo.push(SetOption(self.options, name, bool(value)))

    @property
    def can_calibrate(self) -> bool:
        return self.target is not None and len(self.pairs.usable()) >= self.options.required_pairs

    def set_target(self, component: str) -> None:
        self.target = component
        self.target_changed.emit(component)

    # --- edits (all undoable) ---------------------------------------------------------------
    def pick_3d(self, component: str, feature: str | None, point_world_mm) -> int:
        """``Point``, first half: a 3D point on the model. Returns the new pair's number."""
        if self.target is not None and component != self.target:
            raise CalibrationError(f"pick on the target object '{self.target}' (the click hit '{component}')")
        if self.pairs.pending() is not None:
            raise CalibrationError(f"pair {self.pairs.pending().number} still needs its 2D point on the camera image")
        cmd = AddPoint3D(self.pairs, component, feature, point_world_mm)
        self.undo.push(cmd)
        return cmd.pair.number

    def pick_2d(self, pixel, view=None) -> int:
        """``Point``, second half: the same point on the camera image (px), picked on ``view`` (a
        :class:`~calib_core.calibration.view_stamp.ViewStamp`)."""
        pending = self.pairs.pending()
        if pending is None:
            raise CalibrationError("pick the point on the model (virtual camera) first, then on the camera image")
        self.undo.push(SetPixel(self.pairs, pending.number, pixel, view))
        return pending.number

    def move_2d(self, number: int, pixel, view=None) -> None:
        self.undo.push(SetPixel(self.pairs, number, pixel, view))

    def delete(self, number: int) -> None:
        self.undo.push(DeletePair(self.pairs, number))

    def set_enabled(self, number: int, enabled: bool) -> None:
        self.undo.push(SetEnabled(self.pairs, number, enabled))

    def clear(self) -> None:
        self.undo.push(ClearPairs(self.pairs))

    # --- solve ---------------------------------------------------------------------------------
    def calibrate(
        self,
        intrinsics: Intrinsics,
        obj2world: np.ndarray,
        cam2world_model: np.ndarray,
        tcp2base_model: np.ndarray,
        joints_deg=None,
        *,
        form_tolerance_mm: float = 0.0,
    ) -> EndEffectorEstimate:
        """``Calibrate``: solve the camera pose from the usable pairs (in the target's frame) with
        the modelled camera pose as the prior, and the real end-effector location from it; its uncertainty carries the
        target's ``form_tolerance_mm`` (1-sigma of its features about their CAD positions)."""
        if self.target is None:
            raise CalibrationError("choose the target object first")
        use, needed = self.pairs.usable(), self.options.required_pairs
        if len(use) < needed:
            why = " (focal lengths are estimated)" if self.options.estimate_focal else ""
            raise CalibrationError(f"{len(use)} complete pairs; calibrating needs {needed}{why}")
        points_world, pixels, numbers = self.pairs.arrays()
        points_obj = apply(invert(obj2world), points_world)
        prior = concat(obj2world, invert(cam2world_model))
        from calib_core.solver.errors import named_points
        from calib_core.solver.solve import solve_pose  # the solver's compiled kernels load on the first solve

        how = dict(prior=prior, estimate_focal=self.options.estimate_focal, robust=self.options.robust)
        with named_points("pair", numbers):  # messages name pairs by the numbers the table shows
            solution = solve_pose(points_obj, pixels, intrinsics, **how)
        return self.show_result(
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

    def show_result(
        self,
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
        """Make ``solution`` this session's result. With a ``label`` it is an operator's solve: one
        command on the undo stack (undo brings the previous result back); without, a solve shown from
        elsewhere (a recording being replayed), which is not an edit. With the solve's
        ``points_obj_mm`` (m, 3, the target's frame) and ``intrinsics`` the result's covariance
        carries the image points' shared error
        (:func:`~calib_core.calibration.end_effector.shared_shift_covariance`) and the target's
        ``form_tolerance_mm`` (:func:`~calib_core.calibration.form_error.form_error_covariance`). ``view_sources``:
        the recordings the look's frames came from, by name (default: the used pairs' stamps; empty: all live).
        ``inputs``: the solve's inputs as a recording keeps them."""
        used = [p for p in self.pairs if p.number in set(numbers)]
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
            self.result.inputs = inputs
        solved = Solved(estimate, context, 0)
        if label is None:
            self.result.show(solved)
        else:
            self.undo.push(ShowSolved(self.result, solved, label))
        return estimate

    def choose_candidate(self, index: int) -> None:
        """Take candidate ``index`` of an ambiguous solve as the answer (undoable)."""
        self.undo.push(ChooseCandidate(self.result, index))

    @property
    def stale_reason(self) -> str | None:
        """Why the result no longer belongs to the pairs on screen (``None``: it does, or there is none)."""
        return self.result.stale_reason(self.pairs.usable())

    def storable_estimate(self):
        """The last solve's estimate, when it may be stored as a correction; else :class:`CalibrationError` saying
        why: there is none, it failed, or the pairs changed since (the stale result is said before anything else is
        asked of the look)."""
        r = self.result.estimate
        if r is None:
            raise CalibrationError("calibrate first")
        stale = self.stale_reason
        if stale:
            raise CalibrationError(f"the result is from an earlier state ({stale}); nothing stored")
        if r.solution.status is SolveStatus.FAILED:
            raise CalibrationError(f"the last solve failed ({r.solution.reason}); nothing to store")
        return r

    def store_correction(self, task: str, source: str = "", **how) -> Correction:
        """``Store correction`` for a task location from the last solve, undoable; ``how``: the confirmation, the look
        fused with a calibrated robot, a measured tool's covariance and the kind
        (:func:`~calib_core.calibration.correction_from_look.correction_from_look`). Raises
        :class:`CalibrationError` when there is no result to store, it failed or the pairs changed since."""
        r = self.storable_estimate()
        verdict = self.result.verdict or self.result.judge(r)
        correction = correction_from_look(r, self.result.context, verdict, task, source, **how)
        self.undo.push(StoreCorrection(self.corrections, correction))
        return correction
