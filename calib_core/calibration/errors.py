"""What a calibration step raises when it cannot be taken now."""

from __future__ import annotations

from calib_core.errors import OperatorError


class CalibrationError(OperatorError):
    """A calibration step that cannot be taken now; the message says what to do instead."""


class ConfirmationNeeded(CalibrationError):
    """The step can be taken only with the operator's explicit confirmation (``reasons``: why)."""

    def __init__(self, message: str, reasons: tuple[str, ...]):
        super().__init__(message)
        self.reasons = reasons
