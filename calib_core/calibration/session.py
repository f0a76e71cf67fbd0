"""A calibration session: the target object, the pairs, the solve's options, the result and the corrections, with
one undo stack for every edit of them.

This is the calibration mode of the paper's command window without the window: ``Target object``, ``Point`` (3D
then 2D), ``Accept``, ``Calibrate``, ``Store correction``. Each concept has its owner, which the views subscribe to:
``pairs`` (:class:`~calib_core.calibration.correspondences.CorrespondenceSet`), ``options``
(:class:`~calib_core.calibration.solve_options.SolveOptions`), ``result`` (the last solve and its verdict,
:class:`~calib_core.calibration.look_result.LookResult`), ``corrections``
(:class:`~calib_core.calibration.corrections.CorrectionTable`); every edit of them is a command that checks itself,
pushed on ``undo`` (the pairs' in :mod:`~calib_core.calibration.commands`, a store
:class:`~calib_core.calibration.correction_from_look.StoreLook`, an option
:class:`~calib_core.calibration.solve_options.SetOption`); the solve is a service
(:func:`~calib_core.calibration.look_solving.calibrate`).
"""

from __future__ import annotations

from psygnal import Signal

from calib_core.calibration.corrections import CorrectionTable
from calib_core.calibration.correspondences import CorrespondenceSet
from calib_core.calibration.look_result import LookResult
from calib_core.calibration.solve_options import SolveOptions
from calib_core.undo import UndoStack


class CalibrationSession:
    """One calibration's owners and the target they are about. Event (psygnal): ``target_changed(name)``."""

    target_changed = Signal(object)

    def __init__(self) -> None:
        self.pairs = CorrespondenceSet()
        self.undo = UndoStack()
        self.corrections = CorrectionTable()
        self.options = SolveOptions()
        self.result = LookResult()
        self.target: str | None = None

    def set_target(self, component: str) -> None:
        self.target = component
        self.target_changed.emit(component)

    @property
    def can_calibrate(self) -> bool:
        return self.target is not None and len(self.pairs.usable()) >= self.options.required_pairs

    @property
    def stale_reason(self) -> str | None:
        """Why the result no longer belongs to the pairs on screen (``None``: it does, or there is none)."""
        return self.result.stale_reason(self.pairs.usable())
