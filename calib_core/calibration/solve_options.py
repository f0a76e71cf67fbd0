"""The solve's options the operator sets: estimate the focal lengths, solve robustly."""

from __future__ import annotations

from psygnal import Signal

from calib_core.calibration.errors import CalibrationError
from calib_core.undo import Command


class SolveOptions:
    """``estimate_focal`` (the focal lengths are solved for, with four pairs at least) and ``robust`` (pairs that
    disagree with the rest are left out). Event (psygnal): ``changed(name, value)`` when one changed."""

    NAMES = ("estimate_focal", "robust")

    changed = Signal(str, object)

    def __init__(self) -> None:
        self.estimate_focal = False
        self.robust = False

    @property
    def required_pairs(self) -> int:
        """The fewest pairs a solve with these options needs."""
        return 4 if self.estimate_focal else 3

    def check(self, name: str) -> str:
        if name not in self.NAMES:
            raise CalibrationError(f"no solve option {name!r}; options: {', '.join(self.NAMES)}")
        return name

    def apply(self, name: str, value: bool) -> None:
        setattr(self, self.check(name), bool(value))
        self.changed.emit(name, bool(value))


class SetOption(Command):
    """Set one solve option; undo sets it back."""

    def __init__(self, options: SolveOptions, name: str, value: bool):
        self.options, self.name, self.value = options, options.check(name), bool(value)
        self.old = getattr(options, name)
        self.label = f"{'Use' if value else 'Stop using'} the {name.replace('_', ' ')} option"

    @property
    def changes_nothing(self) -> bool:
        return self.old == self.value

    def do(self) -> None:
        self.options.apply(self.name, self.value)

    def undo(self) -> None:
        self.options.apply(self.name, self.old)
