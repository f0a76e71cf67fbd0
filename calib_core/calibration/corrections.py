"""The correction table: for each task location, the measured displacement of the real end
effector from the model, with its history, and the corrected target to command."""

from __future__ import annotations

from psygnal import Signal

import time
from dataclasses import dataclass, field

import numpy as np

from calib_core.names import one_line
from calib_core.frames import concat, invert
from calib_core.undo import Command


@dataclass(frozen=True)
class Correction:
    """One stored calibration of a task location.

    ``tcp2base_model``/``tcp2base_measured`` (4, 4) mm at ``joints_deg``; ``displacement_mm``,
    ``rotation_deg`` (3,) with 1-sigma; ``rms_px`` and ``pairs`` of the solve; ``time_s``
    (Unix time); ``source``: where it came from (e.g. a recording and pick numbers); ``verdict``
    of the result (``ok``, or what the operator confirmed) and ``confirmation``: who confirmed a
    result that was not ``ok``, when and why (empty for an ``ok`` one). ``kind``: ``correction``
    (commanded when the task is executed) or ``measurement`` (a look made at another pose or on a
    recording, kept as what it is: never commanded)."""

    task: str
    tcp2base_model: np.ndarray
    tcp2base_measured: np.ndarray
    displacement_mm: np.ndarray
    rotation_deg: np.ndarray
    std_displacement_mm: np.ndarray
    std_rotation_deg: np.ndarray
    joints_deg: np.ndarray
    rms_px: float
    pairs: int
    time_s: float = field(default_factory=time.time)
    source: str = ""
    verdict: str = "ok"
    confirmation: str = ""
    kind: str = "correction"

    def __post_init__(self) -> None:
        # the notes go into exports as remarks: one line each, whatever the operator typed
        object.__setattr__(self, "source", one_line(self.source))
        object.__setattr__(self, "confirmation", one_line(self.confirmation))

    @property
    def delta_base(self) -> np.ndarray:
        """``Δ`` with ``tcp_real = Δ @ tcp_model`` (base frame) near this location."""
        return concat(invert(self.tcp2base_model), self.tcp2base_measured)


class CorrectionTable:
    """Corrections per task location, oldest first. Event: ``changed(task)`` on every add or removal."""

    changed = Signal(str)

    def __init__(self) -> None:
        self._table: dict[str, list[Correction]] = {}
        self._verifications: dict[str, list] = {}

    def add_verification(self, verification) -> None:
        """A second look after executing a correction (a
        :class:`~calib_core.calibration.verification.Verification`), kept with the location's history."""
        self._verifications.setdefault(verification.task, []).append(verification)
        self.changed.emit(verification.task)

    def replace_with(self, other: CorrectionTable) -> None:
        """Every correction and verification of ``other`` in place of this table's (a workspace opened)."""
        tasks = set(self._table) | set(other._table) | set(self._verifications) | set(other._verifications)
        self._table = {t: list(h) for t, h in other._table.items()}
        self._verifications = {t: list(v) for t, v in other._verifications.items()}
        for task in sorted(tasks):
            self.changed.emit(task)

    def verifications(self, task: str) -> list:
        return list(self._verifications.get(task, []))

    def add(self, correction: Correction) -> None:
        self._table.setdefault(correction.task, []).append(correction)
        self.changed.emit(correction.task)

    def remove_last(self, task: str) -> Correction:
        """Take the newest entry of ``task``'s history away (undo of a store)."""
        c = self._table[task].pop()
        if not self._table[task]:
            del self._table[task]
        self.changed.emit(task)
        return c

    def history(self, task: str) -> list[Correction]:
        return list(self._table.get(task, []))

    def latest(self, task: str) -> Correction | None:
        """The newest *correction* of ``task`` (measurements are never commanded); ``None`` if none."""
        corrections = [c for c in self._table.get(task, []) if c.kind == "correction"]
        return corrections[-1] if corrections else None

    def tasks(self) -> list[str]:
        """Every task location with something stored: a correction or a measurement."""
        return list(self._table)

    def corrected_tasks(self) -> list[str]:
        """The task locations that hold a correction (what is commanded; a measurement never is)."""
        return [task for task in self._table if self.latest(task) is not None]

    def measured_only(self) -> list[str]:
        """The task locations that hold measurements and no correction: nothing of theirs is commanded or exported
        as a target."""
        return [task for task in self._table if self.latest(task) is None]

    def corrected_target(self, task: str, target2base: np.ndarray) -> np.ndarray:
        """The pose (4, 4) mm to command through the model so the real TCP reaches ``target2base``:
        ``Δ^-1 @ target``, with ``Δ`` the latest correction (the target itself when there is none)."""
        c = self.latest(task)
        return target2base.copy() if c is None else concat(target2base, invert(c.delta_base))


class StoreCorrection(Command):
    """Store ``correction`` in ``table``; undo takes it away again."""

    def __init__(self, table: CorrectionTable, correction: Correction):
        self.table, self.correction = table, correction
        self.label = f"Store {correction.kind} for {correction.task}"

    def do(self) -> None:
        self.table.add(self.correction)

    def undo(self) -> None:
        self.table.remove_last(self.correction.task)
