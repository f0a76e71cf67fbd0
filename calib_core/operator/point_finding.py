"""*Find points*: the target's features located in the held frame and proposed as pairs, accepted
in one undoable step. A part of :class:`~calib_core.operator.core.OperatorCore` (``core.finder``), given the
cell, the session, the picking (the pair being made), the frames (the held one), the refinement of picks (what
it reads from a frame, shared) and the log.

The frame is held as for a pick (refused while the robot moves), so the proposals carry its
:class:`~calib_core.calibration.view_stamp.ViewStamp`; the modelled camera pose is the robot model's
at the frame's joints. Nothing here moves the robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from psygnal import Signal

from calib_core.calibration.commands import AddPairs
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.look_solving import show_solution
from calib_core.calibration.session import CalibrationSession
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.errors import OperatorError
from calib_core.frames import apply, concat, invert
from calib_core.operator.cell import Cell
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.frame_holding import FrameHolding, refuse_mixed_poses
from calib_core.operator.pick_refining import PickRefining
from calib_core.operator.picking import Picking

if TYPE_CHECKING:  # imported when first used: Find points loads the renderer and its detectors
    from calib_core.look.found_points import FoundPoints


@dataclass(frozen=True)
class FoundOnFrame:
    """A Find points result and the frame it was found on."""

    result: FoundPoints
    view: ViewStamp


class PointFinding:
    """Events: ``points_found(found)`` (a :class:`FoundOnFrame`; ``None``: the proposals withdrawn),
    ``solved()`` after :meth:`calibrate_on_edges`."""

    points_found = Signal(object)
    solved = Signal()

    def __init__(
        self,
        cell: Cell,
        session: CalibrationSession,
        picking: Picking,
        frames: FrameHolding,
        refining: PickRefining,
        log: OperatorLog,
    ):
        self._cell, self._session, self._picking, self._log = cell, session, picking, log
        self._frames, self._refining = frames, refining
        self.found: FoundOnFrame | None = None
        """The last Find points' result (kept for *Calibrate on edges* after its proposals were accepted or
        dismissed)."""
        self._model_view = None

    def find_points(self) -> FoundOnFrame:
        """Locate the target's features in the held frame (holding the newest one first). Emits
        ``points_found``; the proposals wait for :meth:`accept_found_points`."""
        target = self._session.target
        if target is None:
            raise CalibrationError("choose the target object first")
        was_held = self._frames.still is not None
        held = self._frames.still or self._frames.hold_frame()
        q = np.asarray(held.stamp.joints_deg, dtype=float)
        item = self._cell.workcell.component(target)
        obj2cam_model = concat(item.item2world, invert(self._cell.robot.fk(q, "camera")))
        from calib_core.look.find_points import find_points

        result = find_points(
            self._refining.evidence(held.frame.image),
            self._cell.intrinsics,
            item,
            obj2cam_model,
            expected=self.modelled_view(q, item),
        )
        if not was_held and not result.found and result.edges is None:
            # held for this look, and nothing on it to pick or fit (the target not in view): the next look, after the
            # robot has moved, takes a new frame instead of this one
            self._frames.release_unused_still()
        self.found = FoundOnFrame(result, held.stamp)
        self._log.record(
            "points_found",
            component=target,
            found=result.found,
            proposed=[p.feature for p in result.proposals],
            missed={m.feature: m.reason for m in result.missed},
            seconds=round(result.seconds, 3),
        )
        self.points_found.emit(self.found)
        self._log.say(result.message)
        return self.found

    def dismiss_found_points(self) -> None:
        """The proposals are no longer on offer (their list closed): ``points_found(None)``. The last
        ones stay in :attr:`found` for *Calibrate on edges* and the recording."""
        self.points_found.emit(None)

    def modelled_view(self, q_deg, item):
        """What the modelled camera at joints ``q_deg`` sees of ``item`` (the modelled cell, the robot
        and what is put up in it), for Find points' checks against the image."""
        if self._model_view is None or self._model_view.intrinsics != self._cell.intrinsics:
            from calib_core.render.model_view import ModelView  # VTK loads on the first Find points, not at start-up

            if self._model_view is not None:
                self._model_view.close()
            self._model_view = ModelView(self._cell.intrinsics)
        return self._model_view.of_cell(
            self._cell.workcell.components,
            self._cell.model_visuals(),
            q_deg,
            item.item2world,
            extras=list(self._cell.extras),
        )

    def calibrate_on_edges(self):
        """*Calibrate on edges*: the pose the last Find points' edge refinement found (the target's
        edges on the held frame, hundreds of samples) as this session's result, with no pairs. Emits
        ``solved`` like Calibrate; the solve's inputs are recorded with ``method`` ``edges``."""
        found = self.found
        if found is None or found.result.edges is None:
            raise OperatorError("Find points (F6) first: the edges are fitted on its frame")
        if not found.result.edges.settled:
            raise OperatorError(
                f"the target's edges did not settle on this frame (RMS {found.result.edges.rms_px:.2f} px): pick the "
                "points by hand"
            )
        from calib_core.solver.solve_inputs import solve_inputs
        from calib_core.look.edge_solution import edge_solution

        solution = edge_solution(found.result.edges, self._cell.intrinsics)
        item = self._cell.workcell.component(found.result.component)
        q = np.asarray(found.view.joints_deg, dtype=float)
        cam2world_model = self._cell.robot.fk(q, "camera")
        inputs = solve_inputs(
            np.zeros((0, 3)),
            np.zeros((0, 2)),
            self._cell.intrinsics,
            prior=concat(item.item2world, invert(cam2world_model)),
        )
        inputs.update(method="edges", component=item.name, frame_index=int(found.view.frame_index))
        self._picking.let_go()
        features = np.array(list(item.features.values()), dtype=float).reshape(-1, 3)
        estimate = show_solution(
            self._session,
            solution,
            item.item2world,
            cam2world_model,
            self._cell.robot.fk(q, "tcp"),
            q,
            [],
            points_obj_mm=features,
            intrinsics=self._cell.intrinsics,
            view_sources=(found.view.source,) if found.view.recorded else (),
            label="Calibrate on edges",
            form_tolerance_mm=item.form_tolerance_mm,
            inputs=inputs,
        )
        self.solved.emit()
        return estimate

    def accept_found_points(self, features: list[str] | None = None) -> list[int]:
        """Add the proposals (``features``: those named; default all) as pairs, in one undoable step.
        Features already paired are left out. Returns the new pairs' numbers."""
        found = self.found
        if found is None or not found.result.proposals:
            raise OperatorError("nothing found to accept: Find points (F6) first")
        session = self._session
        pending = session.pairs.pending()
        if pending is not None:
            raise OperatorError(
                f"pair {pending.number} still waits for its point on the camera image: click it there, or delete it, "
                "then accept"
            )
        chosen = [p for p in found.result.proposals if features is None or p.feature in features]
        unknown = set(features or ()) - {p.feature for p in found.result.proposals}
        if unknown:
            raise OperatorError(f"not among the proposals: {', '.join(sorted(unknown))}")
        paired = {p.feature for p in session.pairs if p.component == found.result.component and p.feature}
        fresh = [p for p in chosen if p.feature not in paired]
        if not fresh:
            raise OperatorError(
                f"every proposed feature is already paired ({', '.join(sorted(paired & {p.feature for p in chosen}))})"
            )
        refuse_mixed_poses([p for p in session.pairs if p.complete], found.view)
        item = self._cell.workcell.component(found.result.component)
        spec = [(item.name, p.feature, apply(item.item2world, p.point_mm), p.uv_px) for p in fresh]
        command = AddPairs(session.pairs, spec, found.view)
        session.undo.push(command)
        numbers = [pair.number for pair in command.added]
        self._log.record("found_points_accepted", numbers=numbers, features=[p.feature for p in fresh])
        self.found = None
        return numbers
