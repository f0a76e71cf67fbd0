"""A look's result: the last solve's end-effector estimate, what it was solved from, the candidate chosen of an
ambiguous solve, and its verdict against the cell's limits and the task's tolerance.

The session's ``result`` part (:class:`~calib_core.calibration.session.CalibrationSession`); its commands (a solve
shown, a candidate chosen) go on the session's undo stack like every other edit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from psygnal import Signal

from calib_core.calibration.end_effector import EndEffectorEstimate, end_effector_from_solution, shared_shift_covariance
from calib_core.calibration.form_error import form_error_covariance
from calib_core.calibration.verdict import ResultVerdict, judge
from calib_core.camera.intrinsics import Intrinsics
from calib_core.solver.solution import SolveStatus
from calib_core.calibration.errors import CalibrationError
from calib_core.undo import Command
from calib_core.workcell.safety import SafetyLimits


def pairs_key(pairs) -> dict:
    """The pairs as a solve saw them: number -> (point mm, pixel, view stamp)."""
    return {p.number: (p.point_world_mm, p.pixel, p.view) for p in pairs}


@dataclass(frozen=True)
class SolveContext:
    """What a result was computed from: the target's placement, the modelled camera and TCP poses
    (4, 4) mm at ``joints_deg`` (the joints of the pairs' frame), and the pairs (by number, with
    their points and pixels as they were)."""

    obj2world: np.ndarray
    cam2world_model: np.ndarray
    tcp2base_model: np.ndarray
    joints_deg: np.ndarray | None
    numbers: tuple[int, ...]
    pairs: dict
    points_obj_mm: np.ndarray | None = None
    """The solve's 3D points (m, 3) in the target's frame, for the image points' shared error."""
    intrinsics: Intrinsics | None = None
    view_sources: tuple[str, ...] = ()
    """The recordings the frames of the look came from, by name; empty when every frame was live (a frame's
    :attr:`~calib_core.calibration.view_stamp.ViewStamp.recorded`, never its source's name, says which)."""
    form_tolerance_mm: float = 0.0
    """The target's features about their CAD positions (1-sigma per axis, mm): :attr:`SceneItem.form_tolerance_mm`."""


def shared_covariance(context: SolveContext | None, obj2cam):
    """The result's covariance (6, 6) from what the residuals cannot show: the image points' shared error and the
    target's form tolerance (its features off their CAD positions); None when the solve's points or camera are not
    known."""
    if context is None or context.points_obj_mm is None or context.intrinsics is None:
        return None
    return shared_shift_covariance(obj2cam, context.points_obj_mm, context.intrinsics) + form_error_covariance(
        obj2cam, context.points_obj_mm, context.intrinsics, context.form_tolerance_mm
    )


@dataclass(frozen=True)
class Solved:
    """One state of the result: the ``estimate`` (``None``: no result), its ``context``, the chosen candidate."""

    estimate: EndEffectorEstimate | None = None
    context: SolveContext | None = None
    chosen_candidate: int = 0


class LookResult:
    """The last solve's result and its verdict. ``estimate`` is ``None`` before a solve.

    Event (psygnal): ``changed()`` after every solve shown, candidate chosen, result cleared or verdict judged again.

    Its public members: the result (estimate, context, the chosen candidate, the numbers solved, the solve's inputs),
    its verdict with the limits and the task's tolerance it is judged by, whether it still belongs to the pairs, and the
    changes made to it (show, select, clear, judge).
    """

    changed = Signal()

    def __init__(self) -> None:
        self._solved = Solved()
        self.verdict: ResultVerdict | None = None
        """The verdict of :attr:`estimate` (``None`` before a solve)."""
        self.limits: SafetyLimits | None = None
        """The cell's limits a result is judged against (:meth:`judge_by`; ``None``: the defaults)."""
        self.tolerance_mm: float | None = None
        """The task location's tolerance a result is judged against (``None``: the default)."""
        self.inputs: dict | None = None
        """The last solve's inputs as a recording keeps them (:func:`~calib_core.solver.solve_inputs.solve_inputs`)."""

    @property
    def estimate(self) -> EndEffectorEstimate | None:
        return self._solved.estimate

    @property
    def context(self) -> SolveContext | None:
        return self._solved.context

    @property
    def chosen_candidate(self) -> int:
        return self._solved.chosen_candidate

    @property
    def solved_numbers(self) -> list[int]:
        """The numbers of the pairs the last solve used (empty before a solve)."""
        return list(self.context.numbers) if self.context else []

    def judge_by(self, limits: SafetyLimits | None, tolerance_mm: float | None) -> None:
        """Judge results against the cell's ``limits`` and the task's ``tolerance_mm`` (mm; ``None``: the default);
        the result shown is judged again."""
        self.limits, self.tolerance_mm = limits, tolerance_mm
        if self.estimate is not None:
            self.verdict = self.judge(self.estimate)
            self.changed.emit()

    def judge(self, estimate: EndEffectorEstimate) -> ResultVerdict:
        """``estimate``'s verdict against the limits and tolerance this result is judged by."""
        if self.tolerance_mm is None:
            return judge(estimate, self.limits)
        return judge(estimate, self.limits, self.tolerance_mm)

    def show(self, solved: Solved) -> None:
        """Make ``solved`` the result (judged now: the task, and with it the tolerance, may have changed since)."""
        self._solved = solved
        self.verdict = None if solved.estimate is None else self.judge(solved.estimate)
        self.changed.emit()

    def clear(self) -> None:
        self.show(Solved())

    @property
    def solved(self) -> Solved:
        return self._solved

    def select(self, index: int) -> None:
        """Take candidate ``index`` of an ambiguous solve as the answer (nothing when there is no result)."""
        estimate, context = self.estimate, self.context
        if estimate is None:
            return
        candidates = estimate.solution.candidates
        if not 0 <= index < max(len(candidates), 1):
            raise CalibrationError(f"there is no solution {index + 1}")
        obj2cam = candidates[index].obj2cam if candidates else None
        chosen = end_effector_from_solution(
            estimate.solution,
            context.obj2world,
            context.cam2world_model,
            context.tcp2base_model,
            obj2cam,
            shared_covariance=shared_covariance(context, estimate.solution.obj2cam if obj2cam is None else obj2cam),
        )
        self.show(Solved(chosen, context, index))

    def storable_estimate(self, usable_pairs):
        """The last solve's estimate, when it may be stored as a correction; else :class:`CalibrationError` saying
        why: there is none, the pairs changed since (``usable_pairs``: the pairs on screen; said before anything else
        is asked of the look), or it failed."""
        if self.estimate is None:
            raise CalibrationError("calibrate first")
        stale = self.stale_reason(usable_pairs)
        if stale:
            raise CalibrationError(f"the result is from an earlier state ({stale}); nothing stored")
        if self.estimate.solution.status is SolveStatus.FAILED:
            raise CalibrationError(f"the last solve failed ({self.estimate.solution.reason}); nothing to store")
        return self.estimate

    def stale_reason(self, usable_pairs) -> str | None:
        """Why the result no longer belongs to ``usable_pairs`` (the pairs on screen a solve would use); ``None``:
        it does, or there is none."""
        if self.estimate is None or self.context is None:
            return None
        then, now = self.context.pairs, pairs_key(usable_pairs)
        if then == now:
            return None
        gone = sorted(set(then) - set(now))
        new = sorted(set(now) - set(then))
        moved = sorted(n for n in set(then) & set(now) if then[n] != now[n])
        parts = []
        if gone:
            parts.append(f"{_pairs(gone)} {'are' if len(gone) > 1 else 'is'} no longer used")
        if new:
            parts.append(f"{_pairs(new)} {'were' if len(new) > 1 else 'was'} added")
        if moved:
            parts.append(f"{_pairs(moved)} changed")
        return "; ".join(parts) + " since the solve: calibrate again"


def _pairs(numbers: list[int]) -> str:
    return f"pair{'s' if len(numbers) > 1 else ''} {', '.join(map(str, numbers))}"


class ShowSolved(Command):
    """A solve: the result becomes ``solved``; undo puts back the result it replaced, redo the solve's (not solved
    again)."""

    def __init__(self, result: LookResult, solved: Solved, label: str):
        self.result, self.before, self.solved, self.label = result, result.solved, solved, label

    def do(self) -> None:
        self.result.show(self.solved)

    def undo(self) -> None:
        self.result.show(self.before)


class ChooseCandidate(Command):
    """Take candidate ``index`` of an ambiguous solve as the answer."""

    def __init__(self, result: LookResult, index: int):
        self.result, self.index, self.old = result, index, result.chosen_candidate
        self.label = f"Choose solution {index + 1}"

    def do(self) -> None:
        self.result.select(self.index)

    def undo(self) -> None:
        self.result.select(self.old)
