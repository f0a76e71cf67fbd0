"""The paper's *Point*, *Accept* and *Calibrate* on frames bound to the robot state they were captured in.

A part of :class:`~calib_core.operator.core.OperatorCore` (``core.picking``), given the cell, the session, the
frames (:class:`~calib_core.operator.observations.Observations`), the arm and the log it writes to. Frames arrive
through
:meth:`Picking.observe_frame` (live, or from a recording being replayed); the first image pick of
a set holds the newest frame, only when the robot had settled before it; every image pick
carries that frame's :class:`~calib_core.calibration.view_stamp.ViewStamp`; pairs of two robot
poses are refused.
"""

from __future__ import annotations

import time

import numpy as np
from psygnal import Signal

from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.calibration.view_stamp import ViewStamp
from calib_core.errors import OperatorError
from calib_core.frames import apply, concat, invert
from calib_core.link.joint_history import JointHistory
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.observations import HeldFrame, NotSettledError, Observations
from calib_core.operator.operator_log import OperatorLog
from calib_core.look.corner_pick import refine_corner_pick
from calib_core.look.image_evidence import ImageEvidence


class Picking:
    """Frames, the held still, the pair being made (``current_pair``) and the solve of the pairs.
    Event: ``solved()`` after :meth:`calibrate`."""

    solved = Signal()

    def __init__(self, cell: Cell, session: CalibrationSession, observations: Observations, arm: Arm, log: OperatorLog):
        self.cell, self.session, self.observations, self.arm, self.log = cell, session, observations, arm, log
        self.current_pair: int | None = None
        """The pair being made: picked, not yet accepted (a click on the image moves its point)."""
        self._evidence: ImageEvidence | None = None
        session.pairs.changed.connect(self.release_unused_still)

    def let_go(self) -> None:
        """No pair is being made any more (after an undo, a solve): the next image click starts none."""
        self.current_pair = None

    def calibrate(self):
        """*Calibrate*: solve the usable pairs (all from one robot pose) for the camera's pose, hence the
        tool's; the result is shown through an undoable command. Emits ``solved``."""
        target = self.session.target
        if target is None:
            raise CalibrationError("choose the target object first")
        item = self.cell.workcell.component(target)
        obj2world = item.item2world
        use = self.session.pairs.usable()
        unbound = [p.number for p in use if p.view is None]
        if unbound:
            raise CalibrationError(
                f"pair{'s' if len(unbound) > 1 else ''} {', '.join(map(str, unbound))} "
                f"{'carry' if len(unbound) > 1 else 'carries'} no robot pose "
                "(picked outside the program's frames, or saved by an older videocal): pick the image point again, on "
                "a frame of this pose"
            )
        self.check_same_state(use)
        joints = np.array(use[0].view.joints_deg) if use else self.arm.joints_deg
        self.current_pair = None
        result = self.session.calibrate(
            self.cell.intrinsics,
            obj2world,
            self.cell.robot.fk(joints, "camera"),
            self.cell.robot.fk(joints, "tcp"),
            joints,
            form_tolerance_mm=item.form_tolerance_mm,
        )
        self.solved.emit()
        return result

    def pick_model_point(self, component: str, feature: str | None, point_world_mm) -> int:
        """*Point*, first half: a point on the target's model (3,) mm in base. A new model pick
        replaces a pair still waiting for its image point. Returns the pair's number."""
        pending = self.session.pairs.pending()
        if pending is not None:
            self.session.delete(pending.number)
        self.current_pair = self.session.pick_3d(component, feature, point_world_mm)
        self.log.say(f"pair {self.current_pair}: now pick {feature or 'the point'} on the camera image")
        return self.current_pair

    def pick_image_point(self, pixel, *, refine: bool = False) -> int:
        """*Point*, second half: the same point on the camera image (u, v) px. Until *Accept*, a
        second click moves it. The pick is made on the held frame; the first pick of a set holds
        the newest one, and only when the robot had settled before it (else
        :class:`~calib_core.operator.observations.NotSettledError`, nothing picked). ``refine``: a
        round feature's click moves to its rim's centre, any other to the nearest corner, on the
        held frame."""
        session = self.session
        pending = session.pairs.pending()
        moving = (
            pending is None and self.current_pair is not None and self.current_pair in [p.number for p in session.pairs]
        )
        if pending is None and not moving:
            session.pick_2d(pixel)  # raises with what to do instead
        view = self._view_for_pick(self.current_pair if moving else pending.number)
        if refine:
            pixel = self.refine_pick(self.observations.still.frame.image, pixel)
        if moving:
            session.move_2d(self.current_pair, pixel, view)
        else:
            self.current_pair = session.pick_2d(pixel, view)
        return self.current_pair

    def move_pair_pixel(self, number: int, pixel, *, refine: bool = False) -> None:
        """Move pair ``number``'s image point to ``pixel`` (u, v) px, after Accept too (undoable). The
        point stays on the frame it was picked on: the robot must be shown in that state. ``refine``:
        to the nearest corner on the frame shown (the held one, else the newest)."""
        pair = self.session.pairs.get(number)
        if pair.pixel is None:
            raise OperatorError(f"pair {number} has no image point yet: click it on the camera image")
        view = pair.view
        held = self.observations.still
        if view is not None and held is not None and not held.stamp.same_state(view):
            raise CalibrationError(
                f"pair {number} was picked with the robot at another pose ({view.label}): go back to that pose to move "
                "its point"
            )
        shown = held.frame if held is not None else self.observations.latest
        if refine and shown is not None:
            pixel = refine_corner_pick(self.evidence(shown.image), pixel)
        self.session.move_2d(number, pixel, view)
        self.log.record("pair_moved", number=number, pixel=[float(pixel[0]), float(pixel[1])])

    def _pick_pose(self):
        """The target's pose in the camera for the frame being picked on: ``(obj2cam (4, 4), basis)``, from
        the complete pairs on that frame when there are three or more, else from the model's camera."""
        held = self.observations.still
        joints = np.asarray(held.stamp.joints_deg if held is not None else self.arm.joints_deg, dtype=float)
        obj2world = self.cell.workcell.component(self.session.target).item2world
        obj2cam = concat(obj2world, invert(self.cell.robot.fk(joints, "camera")))
        done = [
            p for p in self.session.pairs.usable() if held is None or p.view is None or p.view.same_state(held.stamp)
        ]
        if len(done) >= 3:
            from calib_core.solver import solve_pose
            from calib_core.solver.errors import SolverInputError

            points = apply(invert(obj2world), np.array([p.point_world_mm for p in done]))
            try:
                solution = solve_pose(points, np.array([p.pixel for p in done]), self.cell.intrinsics, prior=obj2cam)
            except SolverInputError:
                solution = None
            if solution is not None and solution.status.value != "failed":
                return solution.obj2cam, f"from pairs {', '.join(str(p.number) for p in done)}"
        return obj2cam, "from the model"

    def expected_pixel(self):
        """Where the pair waiting for its image point should lie on the frame being picked on: ``(uv (2,)
        px, basis)`` (see :meth:`_pick_pose`); ``None`` when no pair waits."""
        from calib_core.camera.projection import project_points

        pending = self.session.pairs.pending()
        if pending is None or self.session.target is None:
            return None
        obj2cam, basis = self._pick_pose()
        obj2world = self.cell.workcell.component(self.session.target).item2world
        uv = project_points(
            apply(invert(obj2world), np.array(pending.point_world_mm)[None]), obj2cam, self.cell.intrinsics
        )[0]
        return (uv, basis) if np.all(np.isfinite(uv)) else None

    def evidence(self, image: np.ndarray) -> ImageEvidence:
        """What the picks and Find points read from ``image`` (a frame's), kept for the last frame asked: the clicks
        and Find points on one held frame share one grey, one gradient and one edge map."""
        if self._evidence is None or self._evidence.source is not image:
            self._evidence = ImageEvidence(image)
        return self._evidence

    def refine_pick(self, image, pixel) -> tuple[float, float]:
        """``pixel`` (u, v) px on ``image`` refined: to the rim's centre for a round feature
        (:meth:`refine_circle_pick`), else to the nearest corner (``cv2.cornerSubPix``)."""
        centre = self.refine_circle_pick(image, pixel)
        if centre is not None:
            return float(centre[0]), float(centre[1])
        return refine_corner_pick(self.evidence(image), pixel)

    def refine_circle_pick(self, image, pixel):
        """A click on a round feature (the waiting pair's feature is a circle in the workcell) moved to the
        rim's centre: the rim the model predicts, placed at the click, fitted to the image's edges within
        4 px, corrected for perspective. ``None`` when the feature is no circle or no rim was found."""
        from calib_core.camera.projection import project_points
        from calib_core.look.feature_detectors import Detection, detect_circle
        from calib_core.look.target_detectors import circle_rim

        pending = self.session.pairs.pending()
        target = self.session.target
        if pending is None or target is None or pending.feature is None:
            return None
        item = self.cell.workcell.component(target)
        kind = item.feature_kinds.get(pending.feature)
        if kind is None or kind.kind != "circle":
            return None
        obj2cam, _ = self._pick_pose()
        point = np.asarray(item.features[pending.feature], dtype=float)
        rim, offset = circle_rim(point, kind, obj2cam, self.cell.intrinsics)
        centre = project_points(point[None], obj2cam, self.cell.intrinsics)[0]
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

    def _view_for_pick(self, number: int) -> ViewStamp:
        held = self.observations.still
        if held is None:
            held = self.hold_frame()
        others = [p for p in self.session.pairs if p.complete and p.number != number]
        self.check_same_state(others, held.stamp)
        return held.stamp

    def check_same_state(self, pairs, view: ViewStamp | None = None) -> None:
        """Refuse pairs from different robot states: each with ``view`` (or with the first)."""
        stamped = [p for p in pairs if p.view is not None]
        reference = view or (stamped[0].view if stamped else None)
        if reference is None:
            return
        other = [p for p in stamped if not p.view.same_state(reference)]
        if other:
            worst = max(other, key=lambda p: p.view.joint_difference(reference))
            names = ", ".join(str(p.number) for p in other)
            raise CalibrationError(
                f"pair{'s' if len(other) > 1 else ''} {names} {'were' if len(other) > 1 else 'was'} picked with the "
                "robot at another pose "
                f"(a joint differs by {worst.view.joint_difference(reference):.2f} deg from {reference.label}): "
                "one set of pairs must come from one robot pose. Delete them (or Clear), or go back to that pose"
            )

    def hold_frame(self) -> HeldFrame:
        """Hold the newest frame for picking (refused while the robot moves); ``still_changed``."""
        held = self.observations.hold()
        self.log.record(
            "frame_held",
            frame_index=held.stamp.frame_index,
            t_capture_s=held.stamp.t_capture_s,
            joints_deg=list(held.stamp.joints_deg),
        )
        return held

    def frame_to_capture(self) -> tuple:
        """``(frame, stamp)`` for a board view: the newest frame (never a held still), by the same rule as
        a pick (the robot had settled before it; :class:`NotSettledError` otherwise) and taken after the
        last move was sent (a frame from before it shows the board from the pose before). ``stamp`` is
        ``None`` without a robot (no link, no replay): such a view serves the intrinsics only."""
        frame = self.observations.newest_usable()
        if frame is None:
            raise OperatorError("no camera frame yet: start the camera (Execute > Live) or open a recording")
        sent_s = self.arm.last_move_sent_s
        if not self.replaying and sent_s is not None and frame.t_host_s <= sent_s:
            raise NotSettledError(
                f"frame {frame.index} was taken before the last move ({self.arm.state.what}) was sent: wait for a "
                "frame from where the robot stands now"
            )
        has_robot = self.replaying or self.arm.link is not None
        return frame, (self.observations.stamp(frame) if has_robot else None)

    def stamp_frame(self, frame) -> ViewStamp:
        """``frame``'s stamp (its joints at capture), refused while the robot was not settled."""
        return self.observations.stamp(frame)

    def release_frame(self) -> None:
        """Back to the live image for picking (the pairs keep their stamps)."""
        self.observations.release()

    def release_unused_still(self, *_) -> None:
        """Back to the live image when no complete pair is picked on the held frame."""
        if self.observations.still is not None and not any(p.complete for p in self.session.pairs):
            self.release_frame()

    def robot_settled(self):
        """Whether the robot is still now (a :class:`~calib_core.link.joint_history.Stillness`), at the newest frame
        that can be judged (its joint samples arrived), or the newest sample's time."""
        obs = self.observations
        frame = obs.newest_usable()
        t = frame.t_host_s if frame is not None else obs.history.latest_s
        return obs.stillness_at(time.monotonic() if t is None else t)

    def accept_pair(self) -> int:
        """*Accept*: the pair being made is done. Returns its number."""
        pending = self.session.pairs.pending()
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
        self.log.record("pair_accepted", number=number)
        return number

    def delete_pair(self, number: int | None = None) -> int:
        """Delete pair ``number`` (default: the pair being made). Undoable."""
        number = number if number is not None else self.current_pair
        if number is None:
            raise OperatorError("select a pair in the table to delete it")
        self.session.delete(number)
        if number == self.current_pair:
            self.current_pair = None
        return number

    def observe_frame(self, frame, *, replayed: bool = False) -> None:
        """A camera frame arrived: from the camera (the window's worker, a command-line loop) or,
        with ``replayed``, from the recording being replayed. Live frames are ignored during a replay."""
        if self.replaying != replayed:
            return
        self.observations.observe(frame)

    def begin_replay(self, history: JointHistory, name: str) -> None:
        """A recording is being replayed: its frames and joints stand in for the live ones."""
        self.observations.replay(history, name)

    def end_replay(self) -> None:
        self.observations.go_live()

    @property
    def replaying(self) -> bool:
        return self.observations.replaying
