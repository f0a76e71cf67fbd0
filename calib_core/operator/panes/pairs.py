"""The pairs table's model: the point pairs, the last solve's residuals and flags for them, a pair left out."""

from __future__ import annotations

from calib_core.calibration.commands import SetEnabled
from calib_core.calibration.session import CalibrationSession


class PairsTableModel:
    """What the pairs table shows and sets: the ``pairs`` and the last solve's ``result`` (each pair's residual and
    flag); a pair left out of the solve or taken back in (undoable). Events: ``pairs_changed``, ``result_changed``."""

    def __init__(self, session: CalibrationSession):
        self._session = session
        self.pairs = session.pairs
        self.result = session.result
        self.pairs_changed = session.pairs.changed
        self.result_changed = session.result.changed

    def set_enabled(self, number: int, enabled: bool) -> None:
        """Pair ``number`` used by the next solve or left out; an edit that changes nothing is not recorded."""
        self._session.undo.push(SetEnabled(self._session.pairs, number, enabled))
