"""The results panel's model: the last solve, its verdict and whether it still belongs to the pairs and the robot's
state."""

from __future__ import annotations

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.operator.arm import Arm


class ResultsPaneModel:
    """What the results panel shows: the last solve's ``result`` (estimate, verdict, candidates, the pairs it used),
    the ``pairs`` it came from, why it is stale, how many pairs a solve needs, the arm's joints (a result belongs to
    the robot state it was solved at). Events: ``result_changed``, ``pairs_changed``, ``joints_changed``,
    ``corrections_changed`` (a correction stored: the panel's message is about a step past)."""

    def __init__(self, session: CalibrationSession, arm: Arm):
        self._session, self._arm = session, arm
        self.result = session.result
        self.pairs = session.pairs
        self.result_changed = session.result.changed
        self.pairs_changed = session.pairs.changed
        self.joints_changed = arm.joints_changed
        self.corrections_changed = session.corrections.changed

    @property
    def stale_reason(self) -> str | None:
        """Why the result no longer belongs to the pairs (``None``: it does, or there is none)."""
        return self._session.stale_reason

    @property
    def required_pairs(self) -> int:
        return self._session.options.required_pairs

    @property
    def joints_deg(self) -> np.ndarray:
        return self._arm.joints_deg
