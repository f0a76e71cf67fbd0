"""A calibration session: the target object, the pairs, the undo stack, the last result.

This is the calibration mode of the paper's command window without the window: ``Target
object``, ``Point`` (3D then 2D), ``Accept``, ``Calibrate``, ``Store correction``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from psygnal import Signal

import numpy as np

from calib_core.calibration.commands import AddPoint3D, ClearPairs, DeletePair, SetEnabled, SetPixel
from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.calibration.correspondences import CorrespondenceSet
from calib_core.calibration.end_effector import EndEffectorEstimate, end_effector_from_solution
from calib_core.calibration.undo import Command, UndoStack
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import OperatorError
from calib_core.frames import apply, invert
from calib_core.recording.replay import solve_inputs
from calib_core.solver.solution import SolveStatus


class CalibrationError(OperatorError):
    """A calibration step that cannot be taken now; the message says what to do instead."""


class ChooseCandidate(Command):
    """Take candidate ``index`` of an ambiguous solve as the answer."""

    def __init__(self, session: "CalibrationSession", index: int):
        self.session = session
        self.index = index
        self.old: int = session.chosen_candidate
        self.label = f"Choose solution {index + 1}"

    def do(self) -> None:
        self.session._select(self.index)

    def undo(self) -> None:
        self.session._select(self.old)


@dataclass
class CalibrationSession:
    """State of one calibration. ``result`` is the last solve's end-effector estimate."""

    pairs: CorrespondenceSet = field(default_factory=CorrespondenceSet)
    undo: UndoStack = field(default_factory=UndoStack)
    corrections: CorrectionTable = field(default_factory=CorrectionTable)
    target: str | None = None
    estimate_focal: bool = False
    robust: bool = False
    result: EndEffectorEstimate | None = None
    chosen_candidate: int = 0
    _context: tuple | None = None
    last_solve_inputs: dict | None = None

    changed = Signal()
    """After every solve, candidate choice, cleared result or target change."""

    def _changed(self) -> None:
        self.changed.emit()

    @property
    def required_pairs(self) -> int:
        return 4 if self.estimate_focal else 3

    @property
    def can_calibrate(self) -> bool:
        return self.target is not None and len(self.pairs.usable()) >= self.required_pairs

    def set_target(self, component: str) -> None:
        self.target = component
        self._changed()

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

    def pick_2d(self, pixel) -> int:
        """``Point``, second half: the same point on the camera image (px)."""
        pending = self.pairs.pending()
        if pending is None:
            raise CalibrationError("pick the point on the model (virtual camera) first, then on the camera image")
        self.undo.push(SetPixel(self.pairs, pending.number, pixel))
        return pending.number

    def move_2d(self, number: int, pixel) -> None:
        self.undo.push(SetPixel(self.pairs, number, pixel))

    def delete(self, number: int) -> None:
        self.undo.push(DeletePair(self.pairs, number))

    def set_enabled(self, number: int, enabled: bool) -> None:
        self.undo.push(SetEnabled(self.pairs, number, enabled))

    def clear(self) -> None:
        self.undo.push(ClearPairs(self.pairs))

    # --- solve ---------------------------------------------------------------------------------
    def calibrate(self, intrinsics: Intrinsics, obj2world: np.ndarray, cam2world_model: np.ndarray, tcp2base_model: np.ndarray, joints_deg=None) -> EndEffectorEstimate:
        """``Calibrate``: solve the camera pose from the usable pairs (in the target's frame) with
        the modelled camera pose as the prior, and the real end-effector location from it."""
        if self.target is None:
            raise CalibrationError("choose the target object first")
        use = self.pairs.usable()
        if len(use) < self.required_pairs:
            raise CalibrationError(f"{len(use)} complete pairs; calibrating needs {self.required_pairs}{' (focal lengths are estimated)' if self.estimate_focal else ''}")
        points_world, pixels, numbers = self.pairs.arrays()
        points_obj = apply(invert(obj2world), points_world)
        prior = invert(cam2world_model) @ obj2world
        from calib_core.solver.solve import solve_pose  # the solver's compiled kernels load on the first solve

        solution = solve_pose(points_obj, pixels, intrinsics, prior=prior, estimate_focal=self.estimate_focal, robust=self.robust)
        self.last_solve_inputs = solve_inputs(points_obj, pixels, intrinsics, prior=prior, estimate_focal=self.estimate_focal, robust=self.robust)
        return self.show_result(solution, obj2world, cam2world_model, tcp2base_model, joints_deg, numbers)

    def show_result(self, solution, obj2world: np.ndarray, cam2world_model: np.ndarray, tcp2base_model: np.ndarray, joints_deg, numbers: list[int]) -> EndEffectorEstimate:
        """Show a solve made elsewhere (a recording's) as this session's result, as if calibrated here."""
        self._context = (obj2world, cam2world_model, tcp2base_model, None if joints_deg is None else np.asarray(joints_deg, float), list(numbers))
        self.result = end_effector_from_solution(solution, obj2world, cam2world_model, tcp2base_model)
        self.chosen_candidate = 0
        self._changed()
        return self.result

    def clear_result(self) -> None:
        self.restore_result((None, None, 0))

    @property
    def solved_numbers(self) -> list[int]:
        """The numbers of the pairs the last solve used (empty before a solve)."""
        return list(self._context[4]) if self._context else []

    def result_snapshot(self) -> tuple:
        """The last result with what it was solved from, to put back later with :meth:`restore_result`."""
        return self.result, self._context, self.chosen_candidate

    def restore_result(self, snapshot: tuple) -> None:
        self.result, self._context, self.chosen_candidate = snapshot
        self._changed()

    def _select(self, index: int) -> None:
        if self.result is None:
            return
        candidates = self.result.solution.candidates
        if not 0 <= index < max(len(candidates), 1):
            raise CalibrationError(f"there is no solution {index + 1}")
        obj2world, cam_model, tcp_model, _, _ = self._context
        obj2cam = candidates[index].obj2cam if candidates else None
        self.result = end_effector_from_solution(self.result.solution, obj2world, cam_model, tcp_model, obj2cam)
        self.chosen_candidate = index
        self._changed()

    def choose_candidate(self, index: int) -> None:
        self.undo.push(ChooseCandidate(self, index))

    def store_correction(self, task: str, source: str = "") -> Correction:
        """``Store correction`` for a task location from the last solve."""
        r = self.result
        if r is None:
            raise CalibrationError("calibrate first")
        if r.solution.status is SolveStatus.FAILED:
            raise CalibrationError(f"the last solve failed ({r.solution.reason}); nothing to store")
        _, _, _, joints, numbers = self._context
        correction = Correction(task, r.tcp2base_model, r.tcp2base_measured, r.displacement_mm, r.rotation_deg, r.std_displacement_mm, r.std_rotation_deg, np.zeros(0) if joints is None else joints, r.solution.rms_px, len(numbers), source=source or f"pairs {', '.join(map(str, numbers))}")
        self.undo.push(_StoreCorrection(self.corrections, correction))
        return correction


class _StoreCorrection(Command):
    def __init__(self, table: CorrectionTable, correction: Correction):
        self.table = table
        self.correction = correction
        self.label = f"Store correction for {correction.task}"

    def do(self) -> None:
        self.table.add(self.correction)

    def undo(self) -> None:
        self.table.remove_last(self.correction.task)
