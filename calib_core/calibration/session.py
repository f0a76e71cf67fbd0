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
from calib_core.calibration.end_effector import EndEffectorEstimate, end_effector_from_solution, shared_shift_covariance
from calib_core.calibration.form_error import form_error_covariance
from calib_core.undo import Command, UndoStack
from calib_core.calibration.verdict import ResultVerdict, judge
from calib_core.workcell.safety import SafetyLimits
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import OperatorError
from calib_core.frames import apply, concat, invert
from calib_core.solver.solve_inputs import solve_inputs
from calib_core.solver.solution import SolveStatus


class CalibrationError(OperatorError):
    """A calibration step that cannot be taken now; the message says what to do instead."""


class ConfirmationNeeded(CalibrationError):
    """The step can be taken only with the operator's explicit confirmation (``reasons``: why)."""

    def __init__(self, message: str, reasons: tuple[str, ...]):
        super().__init__(message)
        self.reasons = reasons


def _pairs_key(pairs) -> dict:
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
    view_sources: tuple[str, ...] = ("live",)
    """Where the frames of the look came from: ``live``, or a recording's name (see
    :class:`~calib_core.calibration.view_stamp.ViewStamp`)."""
    form_tolerance_mm: float = 0.0
    """The target's features about their CAD positions (1-sigma per axis, mm): :attr:`SceneItem.form_tolerance_mm`."""


def _shared(context: SolveContext | None, obj2cam):
    """The result's covariance (6, 6) from what the residuals cannot show: the image points' shared error and the
    target's form tolerance (its features off their CAD positions); None when the solve's points or camera are not
    known."""
    if context is None or context.points_obj_mm is None or context.intrinsics is None:
        return None
    return shared_shift_covariance(obj2cam, context.points_obj_mm, context.intrinsics) + form_error_covariance(
        obj2cam, context.points_obj_mm, context.intrinsics, context.form_tolerance_mm
    )


class _ShowResult(Command):
    """A solve: the session's result becomes ``solved`` (result, context, chosen candidate);
    undo puts back the result it replaced, redo the solve's (not solved again)."""

    def __init__(self, session: "CalibrationSession", solved: tuple, label: str):
        self.session = session
        self.before = session.result_snapshot()
        self.solved = solved
        self.label = label

    # The verdict is judged again on each: the task, and with it the tolerance, may have changed since.
    def do(self) -> None:
        self.session.restore_result(self.solved)

    def undo(self) -> None:
        self.session.restore_result(self.before[:3])


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
    _context: SolveContext | None = None
    last_solve_inputs: dict | None = None
    verdict: ResultVerdict | None = None
    """The last result's verdict (``None`` before a solve)."""
    limits: SafetyLimits | None = None
    """The cell's limits a result is judged against (:meth:`judge_by`; ``None``: the defaults)."""
    tolerance_mm: float | None = None
    """The task location's tolerance a result is judged against (``None``: the default)."""

    changed = Signal()
    """After every solve, candidate choice, cleared result or target change."""
    option_changed = Signal(str, object)
    """``(name, value)`` when a solve option (``estimate_focal``, ``robust``) changed."""

    SOLVE_OPTIONS = ("estimate_focal", "robust")

    def _changed(self) -> None:
        self.changed.emit()

    def set_option(self, name: str, value: bool) -> None:
        """Set a solve option through the undo stack (nothing happens when it already has ``value``)."""
        if name not in self.SOLVE_OPTIONS:
            raise CalibrationError(f"no solve option {name!r}; options: {', '.join(self.SOLVE_OPTIONS)}")
        if getattr(self, name) != bool(value):
            self.undo.push(_SetOption(self, name, bool(value)))

    def _apply_option(self, name: str, value: bool) -> None:
        setattr(self, name, value)
        self.option_changed.emit(name, value)

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
        use = self.pairs.usable()
        if len(use) < self.required_pairs:
            raise CalibrationError(
                f"{len(use)} complete pairs; calibrating needs {self.required_pairs}{' (focal lengths are estimated)' if self.estimate_focal else ''}"
            )
        points_world, pixels, numbers = self.pairs.arrays()
        points_obj = apply(invert(obj2world), points_world)
        prior = concat(obj2world, invert(cam2world_model))
        from calib_core.solver.errors import named_points
        from calib_core.solver.solve import solve_pose  # the solver's compiled kernels load on the first solve

        with named_points("pair", numbers):  # messages name pairs by the numbers the table shows
            solution = solve_pose(
                points_obj, pixels, intrinsics, prior=prior, estimate_focal=self.estimate_focal, robust=self.robust
            )
        self.last_solve_inputs = solve_inputs(
            points_obj, pixels, intrinsics, prior=prior, estimate_focal=self.estimate_focal, robust=self.robust
        )
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
    ) -> EndEffectorEstimate:
        """Make ``solution`` this session's result. With a ``label`` it is an operator's solve: one
        command on the undo stack (undo brings the previous result back); without, a solve shown from
        elsewhere (a recording being replayed), which is not an edit. With the solve's
        ``points_obj_mm`` (m, 3, the target's frame) and ``intrinsics`` the result's covariance
        carries the image points' shared error
        (:func:`~calib_core.calibration.end_effector.shared_shift_covariance`) and the target's
        ``form_tolerance_mm`` (:func:`~calib_core.calibration.form_error.form_error_covariance`). ``view_sources``:
        where the look's frames came from (default: the used pairs' stamps)."""
        used = [p for p in self.pairs if p.number in set(numbers)]
        points = None if points_obj_mm is None else np.asarray(points_obj_mm, dtype=float).reshape(-1, 3)
        if view_sources is None:
            view_sources = tuple(sorted({p.view.source for p in used if p.view is not None})) or ("live",)
        context = SolveContext(
            obj2world,
            cam2world_model,
            tcp2base_model,
            None if joints_deg is None else np.asarray(joints_deg, float),
            tuple(numbers),
            _pairs_key(used),
            points,
            intrinsics,
            tuple(view_sources),
            float(form_tolerance_mm),
        )
        result = end_effector_from_solution(
            solution, obj2world, cam2world_model, tcp2base_model, shared_covariance=_shared(context, solution.obj2cam)
        )
        solved = (result, context, 0)  # the verdict is judged where it is shown (restore_result)
        if label is None:
            self.restore_result(solved)
        else:
            self.undo.push(_ShowResult(self, solved, label))
        return result

    def judge_by(self, limits: SafetyLimits | None, tolerance_mm: float | None) -> None:
        """Judge results against the cell's ``limits`` and the task's ``tolerance_mm`` (mm; ``None``: the default);
        the result shown is judged again."""
        self.limits, self.tolerance_mm = limits, tolerance_mm
        self.rejudge()

    def _judge(self, estimate) -> ResultVerdict:
        if self.tolerance_mm is None:
            return judge(estimate, self.limits)
        return judge(estimate, self.limits, self.tolerance_mm)

    def rejudge(self) -> None:
        """Judge the result again (the task, and with it the tolerance, changed)."""
        if self.result is not None:
            self.verdict = self._judge(self.result)
            self._changed()

    def clear_result(self) -> None:
        self.restore_result((None, None, 0, None))

    @property
    def solved_numbers(self) -> list[int]:
        """The numbers of the pairs the last solve used (empty before a solve)."""
        return list(self._context.numbers) if self._context else []

    @property
    def context(self) -> SolveContext | None:
        return self._context

    @property
    def stale_reason(self) -> str | None:
        """Why the result no longer belongs to the pairs on screen (``None``: it does, or there is none)."""
        if self.result is None or self._context is None:
            return None
        then, now = self._context.pairs, _pairs_key(self.pairs.usable())
        if then == now:
            return None
        gone = sorted(set(then) - set(now))
        new = sorted(set(now) - set(then))
        moved = sorted(n for n in set(then) & set(now) if then[n] != now[n])
        parts = []
        if gone:
            parts.append(
                f"pair{'s' if len(gone) > 1 else ''} {', '.join(map(str, gone))} {'are' if len(gone) > 1 else 'is'} no longer used"
            )
        if new:
            parts.append(
                f"pair{'s' if len(new) > 1 else ''} {', '.join(map(str, new))} {'were' if len(new) > 1 else 'was'} added"
            )
        if moved:
            parts.append(f"pair{'s' if len(moved) > 1 else ''} {', '.join(map(str, moved))} changed")
        return "; ".join(parts) + " since the solve: calibrate again"

    def result_snapshot(self) -> tuple:
        """The last result with what it was solved from, to put back later with :meth:`restore_result`."""
        return self.result, self._context, self.chosen_candidate, self.verdict

    def restore_result(self, snapshot: tuple) -> None:
        self.result, self._context, self.chosen_candidate = snapshot[:3]
        self.verdict = snapshot[3] if len(snapshot) > 3 else (None if self.result is None else self._judge(self.result))
        self._changed()

    def _select(self, index: int) -> None:
        if self.result is None:
            return
        candidates = self.result.solution.candidates
        if not 0 <= index < max(len(candidates), 1):
            raise CalibrationError(f"there is no solution {index + 1}")
        c = self._context
        obj2cam = candidates[index].obj2cam if candidates else None
        self.result = end_effector_from_solution(
            self.result.solution,
            c.obj2world,
            c.cam2world_model,
            c.tcp2base_model,
            obj2cam,
            shared_covariance=_shared(c, self.result.solution.obj2cam if obj2cam is None else obj2cam),
        )
        self.chosen_candidate = index
        self.verdict = self._judge(self.result)
        self._changed()

    def choose_candidate(self, index: int) -> None:
        self.undo.push(ChooseCandidate(self, index))

    def store_correction(
        self,
        task: str,
        source: str = "",
        *,
        confirmation: str = "",
        fused=None,
        tool_covariance: np.ndarray | None = None,
        kind: str = "correction",
    ) -> Correction:
        """``Store correction`` for a task location from the last solve. A result that is not ``ok``
        (implausible, uncertain, ambiguous) raises :class:`ConfirmationNeeded` unless
        ``confirmation`` says who accepted it and why; that text is stored with the correction.
        ``fused``: the look weighed against a calibrated robot
        (:class:`~calib_core.calibration.look_fusion.FusedCorrection`): stored in the look's place
        when they agree; when they do not, storing the look alone needs the same confirmation.
        ``tool_covariance`` (6, 6: mm, deg, base axes): a measured tool's, which the look reaches the
        TCP through; added to a look stored alone (a fused one holds it already). ``kind``:
        ``measurement`` keeps the look as what it is, never commanded (no confirmation needed: it moves
        nothing)."""
        r = self.result
        if r is None:
            raise CalibrationError("calibrate first")
        if r.solution.status is SolveStatus.FAILED:
            raise CalibrationError(f"the last solve failed ({r.solution.reason}); nothing to store")
        stale = self.stale_reason
        if stale:
            raise CalibrationError(f"the result is from an earlier state ({stale}); nothing stored")
        verdict = self.verdict or self._judge(r)
        if kind == "measurement":
            fused = None  # what this pose measured, alone
        elif not verdict.ok and not confirmation.strip():
            raise ConfirmationNeeded(
                f"the result is {verdict.verdict.value}: {'; '.join(verdict.reasons)}. Storing it needs your confirmation",
                verdict.reasons,
            )
        if fused is not None and not fused.agree and not confirmation.strip():
            raise ConfirmationNeeded(
                f"{fused.message}. Storing the look alone needs your confirmation", (fused.message,)
            )
        c = self._context
        joints, numbers = c.joints_deg, c.numbers
        source = source or (f"pairs {', '.join(map(str, numbers))}" if numbers else "edges")
        measured, d, rv, std_d, std_r = (
            r.tcp2base_measured,
            r.displacement_mm,
            r.rotation_deg,
            r.std_displacement_mm,
            r.std_rotation_deg,
        )
        if fused is not None and fused.agree:
            std = np.sqrt(np.clip(np.diag(fused.covariance), 0.0, None))
            measured, d, rv, std_d, std_r = (
                concat(r.tcp2base_model, fused.delta_base),
                fused.displacement_mm,
                fused.rotation_deg,
                std[:3],
                std[3:],
            )
            source += f"; {fused.message}"
        else:
            if fused is not None:
                source += f"; the look alone ({fused.message})"
            if tool_covariance is not None and r.covariance is not None:
                std = np.sqrt(np.clip(np.diag(r.covariance + tool_covariance), 0.0, None))
                std_d, std_r = std[:3], std[3:]
                source += "; with the measured tool's uncertainty"
        correction = Correction(
            task,
            r.tcp2base_model,
            measured,
            d,
            rv,
            std_d,
            std_r,
            np.zeros(0) if joints is None else joints,
            r.solution.rms_px,
            len(numbers),
            source=source,
            verdict=verdict.verdict.value,
            confirmation="" if verdict.ok and (fused is None or fused.agree) else confirmation.strip(),
            kind=kind,
        )
        self.undo.push(_StoreCorrection(self.corrections, correction))
        return correction


class _StoreCorrection(Command):
    def __init__(self, table: CorrectionTable, correction: Correction):
        self.table = table
        self.correction = correction
        self.label = f"Store {correction.kind} for {correction.task}"

    def do(self) -> None:
        self.table.add(self.correction)

    def undo(self) -> None:
        self.table.remove_last(self.correction.task)


class _SetOption(Command):
    def __init__(self, session: CalibrationSession, name: str, value: bool):
        self.session, self.name, self.value, self.old = session, name, value, getattr(session, name)
        self.label = f"{'Use' if value else 'Stop using'} the {name.replace('_', ' ')} option"

    def do(self) -> None:
        self.session._apply_option(self.name, self.value)

    def undo(self) -> None:
        self.session._apply_option(self.name, self.old)
