"""The paper's *Point*, *Accept* and *Calibrate*: the pair being made, on the frame the robot state it was captured in.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.picking``), given the cell, the session, the frames
(:class:`~calib_core.operator.frame_holding.FrameHolding`: which frame a pick is made on), the refinement of a click
(:class:`~calib_core.operator.pick_refining.PickRefining`), the arm and the log it writes to. Every image pick
carries its frame's :class:`~calib_core.calibration.view_stamp.ViewStamp`; pairs of two robot poses are refused.
"""

from __future__ import annotations

import numpy as np
from psygnal import Signal

from calib_core.calibration.commands import AddPoint3D, DeletePair, SetPixel
from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.look_solving import calibrate
from calib_core.calibration.session import CalibrationSession
from calib_core.errors import OperatorError
from calib_core.frames import apply, invert
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.frame_holding import FrameHolding, refuse_mixed_poses
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.pick_refining import PickRefining


class Picking:
    """The pair being made (``current_pair``) and the solve of the pairs. Event: ``solved()`` after
    :meth:`calibrate`."""

    solved = Signal()

    def __init__(
        self,
        cell: Cell,
        session: CalibrationSession,
        frames: FrameHolding,
        refining: PickRefining,
        arm: Arm,
        log: OperatorLog,
    ):
        self._cell, self._session, self._frames, self._refining = cell, session, frames, refining
        self._arm, self._log = arm, log
        self.current_pair: int | None = None
        """The pair being made: picked, not yet accepted (a click on the image moves its point)."""

    def let_go(self) -> None:
        """No pair is being made any more (after an undo, a solve): the next image click starts none."""
        self.current_pair = None

    def calibrate(self):
        """*Calibrate*: solve the usable pairs (all from one robot pose) for the camera's pose, hence the
        tool's; the result is shown through an undoable command. Emits ``solved``."""
        target = self._session.target
        if target is None:
            raise CalibrationError("choose the target object first")
        item = self._cell.workcell.component(target)
        obj2world = item.item2world
        use = self._session.pairs.usable()
        unbound = [p.number for p in use if p.view is None]
        if unbound:
            raise CalibrationError(
                f"pair{'s' if len(unbound) > 1 else ''} {', '.join(map(str, unbound))} "
                f"{'carry' if len(unbound) > 1 else 'carries'} no robot pose "
                "(picked outside the program's frames, or saved by an older videocal): pick the image point again, on "
                "a frame of this pose"
            )
        refuse_mixed_poses(use)
        joints = np.array(use[0].view.joints_deg) if use else self._arm.joints_deg
        self.current_pair = None
        result = calibrate(
            self._session,
            self._cell.intrinsics,
            obj2world,
            self._cell.robot.fk(joints, "camera"),
            self._cell.robot.fk(joints, "tcp"),
            joints,
            form_tolerance_mm=item.form_tolerance_mm,
        )
        self.solved.emit()
        return result

    def pick_model_point(self, component: str, feature: str | None, point_world_mm) -> int:
        """*Point*, first half: a point on the target's model (3,) mm in base. A new model pick
        replaces a pair still waiting for its image point. Returns the pair's number."""
        pairs = self._session.pairs
        pending = pairs.pending()
        if pending is not None:
            self._session.undo.push(DeletePair(pairs, pending.number))
        pick = AddPoint3D(pairs, component, feature, point_world_mm, self._session.target)
        self.current_pair = self._session.undo.push(pick).number
        self._log.say(f"pair {self.current_pair}: now pick {feature or 'the point'} on the camera image")
        return self.current_pair

    def pick_image_point(self, pixel, *, refine: bool = False) -> int:
        """*Point*, second half: the same point on the camera image (u, v) px. Until *Accept*, a
        second click moves it. The pick is made on the held frame; the first pick of a set holds
        the newest one, and only when the robot had settled before it (else
        :class:`~calib_core.operator.observations.NotSettledError`, nothing picked). ``refine``: a
        round feature's click moves to its rim's centre, any other to the nearest corner, on the
        held frame."""
        session = self._session
        pending = session.pairs.pending()
        moving = (
            pending is None and self.current_pair is not None and self.current_pair in [p.number for p in session.pairs]
        )
        if pending is None and not moving:
            SetPixel(session.pairs, None, pixel).check()  # raises with what to do instead
        view = self._frames.stamp_for_pick(self.current_pair if moving else pending.number)
        if refine:
            pixel = self._refining.refine(self._frames.still.frame.image, pixel)
        number = self.current_pair if moving else None
        self.current_pair = session.undo.push(SetPixel(session.pairs, number, pixel, view)).number
        return self.current_pair

    def move_pair_pixel(self, number: int, pixel, *, refine: bool = False) -> None:
        """Move pair ``number``'s image point to ``pixel`` (u, v) px, after Accept too (undoable). The
        point stays on the frame it was picked on: the robot must be shown in that state. ``refine``:
        to the nearest corner on the frame shown (the held one, else the newest)."""
        pair = self._session.pairs.get(number)
        if pair.pixel is None:
            raise OperatorError(f"pair {number} has no image point yet: click it on the camera image")
        view = pair.view
        held = self._frames.still
        if view is not None and held is not None and not held.stamp.same_state(view):
            raise CalibrationError(
                f"pair {number} was picked with the robot at another pose ({view.label}): go back to that pose to move "
                "its point"
            )
        shown = held.frame if held is not None else self._frames.latest
        if refine and shown is not None:
            pixel = self._refining.nearest_corner(shown.image, pixel)
        self._session.undo.push(SetPixel(self._session.pairs, number, pixel, view))
        self._log.record("pair_moved", number=number, pixel=[float(pixel[0]), float(pixel[1])])

    def expected_pixel(self):
        """Where the pair waiting for its image point should lie on the frame being picked on: ``(uv (2,)
        px, basis)`` (see :meth:`~calib_core.operator.pick_refining.PickRefining.pick_pose`); ``None`` when no pair
        waits."""
        from calib_core.camera.projection import project_points

        pending = self._session.pairs.pending()
        if pending is None or self._session.target is None:
            return None
        obj2cam, basis = self._refining.pick_pose()
        obj2world = self._cell.workcell.component(self._session.target).item2world
        uv = project_points(
            apply(invert(obj2world), np.array(pending.point_world_mm)[None]), obj2cam, self._cell.intrinsics
        )[0]
        return (uv, basis) if np.all(np.isfinite(uv)) else None

    def accept_pair(self) -> int:
        """*Accept*: the pair being made is done. Returns its number."""
        pending = self._session.pairs.pending()
        if pending is not None:
            raise OperatorError(
                f"pair {pending.number} ({pending.feature or 'surface point'}) has no point on the camera image yet: "
                "click it there, then Accept"
            )
        if self.current_pair is None:
            raise OperatorError(
                "nothing to accept: pick a point on the model (virtual camera), then the same point on the camera image"
            )
        number, self.current_pair = self.current_pair, None
        self._log.record("pair_accepted", number=number)
        return number

    def delete_pair(self, number: int | None = None) -> int:
        """Delete pair ``number`` (default: the pair being made). Undoable."""
        number = number if number is not None else self.current_pair
        if number is None:
            raise OperatorError("select a pair in the table to delete it")
        self._session.undo.push(DeletePair(self._session.pairs, number))
        if number == self.current_pair:
            self.current_pair = None
        return number
