"""A click on the camera image moved onto what it was aimed at: a round feature's rim centre, else the nearest corner,
and the pose the picks are judged at.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.refining``), given the cell, the session (the
target and the pairs), the frames and the arm. What it reads from a frame (grey, gradient, edges) is made once per
frame and shared with Find points (:meth:`PickRefining.evidence`).
"""

from __future__ import annotations

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.frames import apply, concat, invert
from calib_core.look.corner_pick import refine_corner_pick
from calib_core.look.image_evidence import ImageEvidence
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.frame_holding import FrameHolding


class PickRefining:
    """Image picks refined on the frame they are made on, and the pose they are judged at."""

    def __init__(self, cell: Cell, session: CalibrationSession, frames: FrameHolding, arm: Arm):
        self._cell, self._session, self._frames, self._arm = cell, session, frames, arm
        self._evidence: ImageEvidence | None = None

    def pick_pose(self):
        """The target's pose in the camera for the frame being picked on: ``(obj2cam (4, 4), basis)``, from
        the complete pairs on that frame when there are three or more, else from the model's camera."""
        held = self._frames.still
        joints = np.asarray(held.stamp.joints_deg if held is not None else self._arm.joints_deg, dtype=float)
        obj2world = self._cell.workcell.component(self._session.target).item2world
        obj2cam = concat(obj2world, invert(self._cell.robot.fk(joints, "camera")))
        done = [
            p for p in self._session.pairs.usable() if held is None or p.view is None or p.view.same_state(held.stamp)
        ]
        if len(done) >= 3:
            from calib_core.solver import solve_pose
            from calib_core.solver.errors import SolverInputError

            points = apply(invert(obj2world), np.array([p.point_world_mm for p in done]))
            try:
                solution = solve_pose(points, np.array([p.pixel for p in done]), self._cell.intrinsics, prior=obj2cam)
            except SolverInputError:
                solution = None
            if solution is not None and solution.status.value != "failed":
                return solution.obj2cam, f"from pairs {', '.join(str(p.number) for p in done)}"
        return obj2cam, "from the model"

    def evidence(self, image: np.ndarray) -> ImageEvidence:
        """What the picks and Find points read from ``image`` (a frame's), kept for the last frame asked: the clicks
        and Find points on one held frame share one grey, one gradient and one edge map."""
        if self._evidence is None or self._evidence.source is not image:
            self._evidence = ImageEvidence(image)
        return self._evidence

    def refine(self, image, pixel) -> tuple[float, float]:
        """``pixel`` (u, v) px on ``image`` refined: to the rim's centre for a round feature
        (:meth:`circle_centre`), else to the nearest corner (``cv2.cornerSubPix``)."""
        centre = self.circle_centre(image, pixel)
        if centre is not None:
            return float(centre[0]), float(centre[1])
        return self.nearest_corner(image, pixel)

    def nearest_corner(self, image, pixel) -> tuple[float, float]:
        """``pixel`` (u, v) px moved to the nearest corner on ``image``."""
        return refine_corner_pick(self.evidence(image), pixel)

    def circle_centre(self, image, pixel):
        """A click on a round feature (the waiting pair's feature is a circle in the workcell) moved to the
        rim's centre: the rim the model predicts, placed at the click, fitted to the image's edges within
        4 px, corrected for perspective. ``None`` when the feature is no circle or no rim was found."""
        from calib_core.camera.projection import project_points
        from calib_core.look.feature_detectors import Detection, detect_circle
        from calib_core.look.target_detectors import circle_rim

        pending = self._session.pairs.pending()
        target = self._session.target
        if pending is None or target is None or pending.feature is None:
            return None
        item = self._cell.workcell.component(target)
        kind = item.feature_kinds.get(pending.feature)
        if kind is None or kind.kind != "circle":
            return None
        obj2cam, _ = self.pick_pose()
        point = np.asarray(item.features[pending.feature], dtype=float)
        rim, offset = circle_rim(point, kind, obj2cam, self._cell.intrinsics)
        centre = project_points(point[None], obj2cam, self._cell.intrinsics)[0]
        evidence = self.evidence(image)
        grey, magnitude = evidence.grey, evidence.grey_magnitude
        found = detect_circle(
            grey, rim + (np.asarray(pixel, float) - centre), offset, search_px=4.0, magnitude=magnitude
        )
        if not isinstance(found, Detection):
            return None
        # again from there in a tight window: the rim nearest, not the strongest edge within reach (a faint
        # boss's base beside its rim)
        again = detect_circle(grey, rim + (found.uv_px - centre), offset, search_px=1.5, magnitude=magnitude)
        return again.uv_px if isinstance(again, Detection) else found.uv_px
