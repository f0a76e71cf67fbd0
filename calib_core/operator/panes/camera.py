"""The camera pane's model: the frames, the pairs being made on them and the result drawn over them."""

from __future__ import annotations

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.camera.intrinsics import Intrinsics
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.frame_holding import FrameHolding
from calib_core.operator.picking import Picking
from calib_core.operator.point_finding import PointFinding


class CameraPaneModel:
    """What the camera pane shows and does: the frames (live, replayed, and the still that picks are made on), the
    pairs being made and the result drawn over them, the arm's joints (what is drawn belongs to a robot state), the
    points Find points proposes; a click's pick and a drag's move.

    Its public members are the pane's whole face: seven events (``frame_observed``, ``still_changed``,
    ``pairs_changed``, ``result_changed``, ``joints_changed``, ``camera_model_changed``, ``points_found``), the
    values drawn (``pairs``, ``result``, ``intrinsics``, ``components``, ``target``, ``stale_reason``, ``still``,
    ``joints_deg``) and five actions on the pairs and the held frame."""

    def __init__(
        self,
        cell: Cell,
        frames: FrameHolding,
        picking: Picking,
        session: CalibrationSession,
        arm: Arm,
        finder: PointFinding,
    ):
        self._cell, self._frames, self._picking, self._session, self._arm = cell, frames, picking, session, arm
        self.frame_observed = frames.frame_observed
        self.still_changed = frames.still_changed
        self.pairs_changed = session.pairs.changed
        self.result_changed = session.result.changed
        self.joints_changed = arm.joints_changed
        self.camera_model_changed = cell.camera_model_changed
        self.points_found = finder.points_found
        self.pairs = session.pairs  # the point pairs: iterated, and the one waiting for its image point
        self.result = session.result  # the last solve: its estimate, candidates and the pairs it used

    @property
    def intrinsics(self) -> Intrinsics:
        return self._cell.intrinsics

    @property
    def components(self) -> dict:
        """The cell's components by name (their meshes drawn as the solve's edges)."""
        return self._cell.workcell.components

    @property
    def target(self) -> str | None:
        """The component being calibrated against."""
        return self._session.target

    @property
    def stale_reason(self) -> str | None:
        """Why the result no longer belongs to the pairs (``None``: it does)."""
        return self._session.stale_reason

    @property
    def still(self):
        """The frame held for picking, or ``None`` (the live image)."""
        return self._frames.still

    @property
    def joints_deg(self) -> np.ndarray:
        """The arm's joints now, degrees."""
        return self._arm.joints_deg

    def hold_frame(self):
        return self._frames.hold_frame()

    def release_frame(self) -> None:
        self._frames.release_frame()

    def pick_image_point(self, pixel, *, refine: bool = False) -> int:
        return self._picking.pick_image_point(pixel, refine=refine)

    def move_pair_pixel(self, number: int, pixel, *, refine: bool = False) -> None:
        self._picking.move_pair_pixel(number, pixel, refine=refine)

    def expected_pixel(self):
        """Where the pair waiting for its image point should lie (see :meth:`Picking.expected_pixel`)."""
        return self._picking.expected_pixel()
