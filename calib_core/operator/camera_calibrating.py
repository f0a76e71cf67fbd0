"""The operator core's camera calibration (``core.vision``): the board views captured from the newest settled frame with
the joints then, the camera's intrinsics and its mounting on the flange calibrated from them and checked, and applied
to the cell or saved; the board put up in the cell and the robot poses that see it.

A part of :class:`~calib_core.operator.core.OperatorCore`, given the cell, the frames (the frame a view is taken
from), the observations (which source it came from), the arm (where the robot stands) and the log; ``board_put_up``
tells whoever shows the cell to a camera (the simulated site) what now stands in it. The window's Vision mode is its
view.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from psygnal import Signal

from calib_core.camera.intrinsics import Intrinsics
from calib_core.calibration.errors import CalibrationError
from calib_core.errors import OperatorError
from calib_core.frames import concat, invert, pose_difference
from calib_core.operator.arm import Arm
from calib_core.operator.cell import Cell
from calib_core.operator.observations import Observations
from calib_core.operator.operator_log import OperatorLog
from calib_core.operator.frame_holding import FrameHolding
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.capture import BoardCapture
from calib_core.vision.intrinsics_calibration import RejectedView
from calib_core.vision.view_checks import view_checks
from calib_core.vision.result_checks import hand_eye_problems, intrinsics_problems, views_with_lost_corners


@dataclass(frozen=True)
class MountingResult:
    """A hand-eye calibration with how far it is from the model's mounting (mm, deg) and what its checks found."""

    calibration: object
    off_model_mm: float
    off_model_deg: float
    problems: list[str]
    views: tuple = ()
    """Each view's :class:`~calib_core.vision.view_checks.ViewCheck` (its residual, its agreement with the others)."""

    def check_of(self, name: str):
        """The :class:`~calib_core.vision.view_checks.ViewCheck` of the view ``name``, ``None`` when it was not in
        this calibration (captured after it)."""
        return next((v for v in self.views if v.name == name), None)


class CameraCalibrating:
    """``capture`` (the board's views), ``intrinsics_result`` and ``mounting`` (the last calibrations, or ``None``),
    ``plan`` (robot poses that see the board). ``changed`` after every capture, removal, calibration or new board;
    ``board_put_up(extras)`` when a board goes up in the cell or comes down (``[]``).

    Its public members are the Vision tab's workflow, a step each: the board (set, placed, shown, the poses that see
    it), the views (capture, read a set, remove), the intrinsics and the mounting (calibrate, check, apply, save) and
    the state the tab shows."""

    changed = Signal()
    board_put_up = Signal(list)

    def __init__(
        self,
        cell: Cell,
        frames: FrameHolding,
        observations: Observations,
        arm: Arm,
        log: OperatorLog,
    ):
        self._cell, self._frames, self._observations, self._arm, self._log = cell, frames, observations, arm, log
        self.capture = BoardCapture(parse_board(DEFAULT_SPEC))
        self.intrinsics_result = None
        self.mounting: MountingResult | None = None
        self.plan: list[np.ndarray] = []
        self.plan_index = 0
        self.board_shown = False

    # --- the board ------------------------------------------------------------------------------
    def set_board(self, spec_text: str) -> None:
        """Use the board ``spec_text`` (``charuco:...``; ``ValueError`` names what is wrong); views of another
        board are set aside (said), and a board shown in the cell is replaced."""
        spec = parse_board(spec_text.strip())
        if str(spec) == str(self.capture.spec):
            return
        if self.capture.views:
            self._log.say(
                f"board changed to {spec}: the {len(self.capture.views)} views of the old board were set aside"
            )
        self.capture = BoardCapture(spec)
        self.plan, self.plan_index = [], 0
        if self.board_shown:
            self.show_board(spec, True)
        self.changed.emit()

    def board_placement(self, spec=None) -> np.ndarray:
        """Where the board stands: the workcell's ``hand_eye_board`` placement, or upright in front of the robot
        within its reach. ``board2base`` (4, 4) mm."""
        from calib_core.vision.board_placement import board_in_cell

        return board_in_cell(spec or self.capture.spec, self._cell.workcell, self._cell.robot)

    def show_board(self, spec=None, on: bool = True) -> np.ndarray:
        """Put a board (this part's, or ``spec``: the robot calibration's) up in the cell, or take it down.
        Returns its ``board2base`` (4, 4) mm."""
        from calib_core.vision.board import board_item

        spec = spec or self.capture.spec
        board2base = self.board_placement(spec)
        extras = [board_item(spec, board2base)] if on else []
        self.board_put_up.emit(list(extras))
        self._cell.put_up(extras)
        if on != self.board_shown:
            self._log.say("calibration board put up in front of the robot" if on else "calibration board taken down")
        self.board_shown = on
        return board2base

    def board_view_plan(self, n: int = 16) -> list[np.ndarray]:
        """Joint vectors (deg/mm) from which the modelled camera sees the board from different directions, in an
        order whose every move (from the current joints on) is free of collisions with the robot itself and the cell
        (the board among it); a pose without such a path is left out."""
        from calib_core.operator.move_preview import joint_path
        from calib_core.vision.board_placement import board_view_joints

        world = self._cell.collision_world()
        spec = self.capture.spec
        plan, q = [], np.asarray(self._arm.joints_deg, dtype=float)
        for goal in board_view_joints(self._cell.robot, self._cell.home_joints, spec, self.board_placement(spec), n):
            if not any(world.check(p) for p in joint_path(q, goal)):
                plan.append(goal)
                q = goal
        return plan

    def next_board_pose(self) -> tuple[np.ndarray, str]:
        """The next planned pose that sees the board (deg/mm) and its name; planned on first use."""
        if not self.plan:
            self.plan = self.board_view_plan()
            if not self.plan:
                raise OperatorError("no reachable robot pose sees the board")
        q = self.plan[self.plan_index % len(self.plan)]
        self.plan_index += 1
        return q, f"board pose {(self.plan_index - 1) % len(self.plan) + 1} of {len(self.plan)}"

    # --- a set read from files -------------------------------------------------------------------
    def read_set(self, path, progress=None) -> tuple[int, int]:
        """The views of a hand-eye set (a pose file: JSON of {image, flange2base}, a CSV of image and joints,
        ROS-Industrial's cal_data.yaml; or a folder holding one; :mod:`calib_core.vision.hand_eye_data`) in place of
        the views captured: each image detected with its recorded flange pose or joints, named by its file. The board
        is the file's when it names one, else the one set. ``(accepted, rejected)``; the file's problems raise
        before anything is replaced. ``progress(done, total) -> bool``, called before each image (a large real
        image's board takes a second to find), ends the reading when it returns False: the views stay as they were."""
        from calib_core.vision.hand_eye_data import load_posed_images

        posed = load_posed_images(path)  # raises, naming the file and field, before anything changes
        spec = parse_board(posed.board_text) if posed.board_text else self.capture.spec
        capture = BoardCapture(spec)
        for k, view in enumerate(posed.views):
            if progress is not None and progress(k, len(posed.views)) is False:
                raise OperatorError(f"reading {posed.source.name} was cancelled: the views are as they were")
            image = posed.read_image(view)
            capture.add(image, view.joints_deg, flange2base=view.flange2base, name=view.image_path.stem)
        self.capture, self.intrinsics_result, self.mounting = capture, None, None
        self._log.say(
            f"{len(capture.views)} of {len(posed.views)} views of {posed.source.name} read"
            + (f"; {len(capture.rejected)} rejected (see the list)" if capture.rejected else "")
        )
        self.changed.emit()
        return len(capture.views), len(capture.rejected)

    # --- capturing ------------------------------------------------------------------------------
    def capture_view(self):
        """Detect the board in the newest frame (taken after the last move, once the robot had settled) and keep it
        with the joints then; a :class:`RejectedView` says why not. Both are said in the log."""
        frame, stamp = self._frames.frame_to_capture()
        joints = None if stamp is None else np.array(stamp.joints_deg)
        view = self.capture.add(
            frame.image,
            joints,
            frame_key=(self._observations.live, self._observations.source, frame.index, frame.t_host_s),
        )
        if isinstance(view, RejectedView):
            self._log.say(f"{view.name} rejected: {view.reason}")
        else:
            lost = views_with_lost_corners([len(v.ids) for v in self.capture.views]).get(len(self.capture.views) - 1)
            self._log.say(
                f"{view.name}: {len(view.ids)} corners"
                + ("" if joints is not None else " (no robot pose: not usable for hand-eye)")
                + (
                    ""
                    if lost is None
                    else f"; it lost corners against its neighbours ({lost:.0f}): look at it, remove it if the board "
                    "was cut off or blurred"
                )
            )
        self.changed.emit()
        return view

    def remove_view(self, name: str) -> None:
        self.capture.remove(name)
        self.changed.emit()

    # --- calibrating ----------------------------------------------------------------------------
    def calibrate_intrinsics(self):
        """The intrinsics from the views (:class:`~calib_core.vision.intrinsics_calibration.IntrinsicsCalibration`)."""
        self.intrinsics_result = self.capture.calibrate_intrinsics()
        self.changed.emit()
        return self.intrinsics_result

    def intrinsics_problems(self) -> list[str]:
        """What the last intrinsics calibration's checks found (against the intrinsics in use)."""
        if self.intrinsics_result is None:
            return []
        return intrinsics_problems(self.intrinsics_result, self._cell.intrinsics)

    def calibrate_mounting(self) -> MountingResult:
        """The camera's mounting on the flange from the views with their joints, through the calibrated intrinsics
        if there are any, with its distance from the model's mounting and its checks."""
        intrinsics = self.intrinsics_result.intrinsics if self.intrinsics_result is not None else self._cell.intrinsics
        robot = self._cell.robot
        calibration = self.capture.calibrate_hand_eye(robot, intrinsics)
        modelled = concat(robot.frame_placement("camera"), invert(robot.frame_placement("flange")))
        d, rot = pose_difference(calibration.cam2flange, modelled)
        off = (float(np.linalg.norm(d)), float(np.linalg.norm(rot)))
        noise = self.intrinsics_result.rms_px if self.intrinsics_result is not None else None
        problems = hand_eye_problems(calibration, off, noise, self._cell.workcell.safety)
        names = [v.name for v in self.capture.views]
        apart = calibration.poses.per_view_mm if calibration.poses is not None else [0.0] * len(names)
        checks = view_checks(names, calibration.per_view_rms_px, apart)
        self.mounting = MountingResult(calibration, off[0], off[1], problems, checks)
        odd = [c for c in checks if not c.agrees]
        if odd:
            self._log.say(
                f"{len(odd)} of {len(checks)} views stand out: "
                + "; ".join(f"{c.name}: {c.why}" for c in odd[:3])
                + " - look at them, and remove those that are wrong"
            )
        self.changed.emit()
        return self.mounting

    # --- using the results ----------------------------------------------------------------------
    def apply_intrinsics(self, intrinsics: Intrinsics, why: str = "camera intrinsics replaced") -> None:
        """Use ``intrinsics`` for picking, solving and the virtual camera (the image size must match)."""
        now = self._cell.intrinsics
        if (intrinsics.width, intrinsics.height) != (now.width, now.height):
            raise CalibrationError(
                f"the calibration is for {intrinsics.width} x {intrinsics.height} px images, the camera gives "
                f"{now.width} x {now.height} px"
            )
        self._cell.use_intrinsics(intrinsics)
        self._log.say(why)

    def apply_cam2flange(self, cam2flange: np.ndarray, why: str = "camera mounting replaced") -> None:
        """Use a measured camera mounting (4, 4) mm on the flange in place of the modelled one."""
        robot = self._cell.robot
        robot.set_frame_placement("camera", concat(cam2flange, robot.frame_placement("flange")))
        self._cell.robot_edited()
        self._log.say(why)

    def apply_calibrated_intrinsics(self, confirmed_problems: list[str] | None = None) -> None:
        """Use the last intrinsics calibration; one that failed its checks only with them confirmed (recorded)."""
        if self.intrinsics_result is None:
            raise OperatorError("calibrate the intrinsics first")
        self._confirmed("intrinsics calibration", self.intrinsics_problems(), confirmed_problems)
        r = self.intrinsics_result
        self.apply_intrinsics(r.intrinsics, f"calibrated intrinsics in use (RMS {r.rms_px:.3f} px)")

    def apply_calibrated_mounting(self, confirmed_problems: list[str] | None = None) -> None:
        """Use the last mounting calibration; one that failed its checks only with them confirmed (recorded)."""
        if self.mounting is None:
            raise OperatorError("calibrate the hand-eye first")
        self._confirmed("camera mounting", self.mounting.problems, confirmed_problems)
        c = self.mounting.calibration
        self.apply_cam2flange(c.cam2flange, f"measured camera mounting in use (RMS {c.rms_px:.3f} px)")

    def _confirmed(self, what: str, problems: list[str], confirmed: list[str] | None) -> None:
        if not problems:
            return
        if confirmed is None or list(confirmed) != list(problems):
            raise OperatorError(f"the {what} failed its checks ({'; '.join(problems)}): confirm it to use it anyway")
        self._log.record("vision_result_confirmed", what=what, problems=list(problems))

    def save_intrinsics(self, path, fmt: str = "opencv") -> None:
        from calib_core.camera.intrinsics_io import save_intrinsics

        save_intrinsics(path, self.intrinsics_result.intrinsics, fmt)
        self._log.say(f"intrinsics saved to {path}")

    def save_mounting(self, path) -> None:
        from calib_core.vision.hand_eye_io import save_hand_eye

        save_hand_eye(path, self.mounting.calibration)
        self._log.say(f"camera mounting saved to {path}")
