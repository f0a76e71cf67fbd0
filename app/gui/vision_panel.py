"""The Vision mode: the view of the core's camera calibration (``core.vision``,
:class:`~calib_core.operator.camera_calibrating.CameraCalibrating`): capture ChArUco board views (live or from a
recording being replayed), see each detection and the image coverage so far, calibrate the intrinsics and the
camera's mounting on the flange, and apply or save the results.

In the simulated cell the board can be put up in front of the robot and the robot stepped through
planned viewing poses; with a real camera the operator holds up or places a board and moves the robot.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QApplication,
    QFileDialog,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QProgressDialog,
    QVBoxLayout,
    QWidget,
)

from app.gui.busy import busy
from app.gui.buttons import button
from app.gui.confirm import ask
from app.gui.error_boundary import guarded
from calib_core.errors import OperatorError
from calib_core.operator.camera_calibrating import CameraCalibrating
from calib_core.vision.board import DEFAULT_SPEC
from calib_core.vision.intrinsics_calibration import RejectedView
from calib_core.vision.result_checks import views_with_lost_corners


class VisionPanel(QWidget):
    """Shows and drives ``vision`` (the core's camera calibration); ``board_detected(corners (n, 2) px or None,
    text)`` tells the camera pane what to draw; ``show_error`` puts a failed step's reason in the window;
    ``move_joints(joints_deg, what)`` steps the robot to a board pose through the window's preview and confirmation.
    Progress goes to the core's log (the status bar)."""

    board_detected = Signal(object, str)

    def __init__(
        self,
        vision: CameraCalibrating,
        show_error: Callable[[str], None],
        move_joints: Callable[[object, str], None],
        say: Callable[[str], None] = lambda text: None,
        parent=None,
    ):
        super().__init__(parent)
        self.vision = vision
        self._say = say  # the operator's log: what the panel declined to do
        self._move_joints = move_joints  # the window previews and confirms moves
        guard = guarded(show_error)
        self._intrinsics_text = ""  # both results stay on screen, one under the other
        self._hand_eye_text = ""

        board = QGroupBox("Board")
        bl = QVBoxLayout(board)
        self.spec = QLineEdit(DEFAULT_SPEC)
        self.spec.setToolTip(
            "charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT[:legacy], chessboard:COLSxROWS:SQUARE_MM, "
            "circles:COLSxROWS:SPACING_MM[:asymmetric], aruco:COLSxROWS:MARKER_MM:GAP_MM:DICT"
        )
        self.spec.editingFinished.connect(guard(self._spec_changed))
        bl.addWidget(self.spec)
        self.show_board = QCheckBox("Board in the simulated cell")
        self.show_board.setToolTip(
            "Put the board up in front of the robot in the simulated cell (the simulated camera sees it)"
        )
        self.show_board.toggled.connect(guard(self._show_board_toggled))
        bl.addWidget(self.show_board)
        self.next_pose = button(
            "Next board pose", "vision_next_pose", "Move the robot (MVJ) to the next planned pose that sees the board"
        )
        self.next_pose.clicked.connect(guard(self._next_pose))
        self.capture_button = button(
            "Capture view",
            "vision_capture",
            "Detect the board in the camera's current frame and keep the view with the robot's joints",
        )
        self.capture_button.clicked.connect(guard(self.capture_view))
        row = QHBoxLayout()
        row.addWidget(self.next_pose)
        row.addWidget(self.capture_button)
        bl.addLayout(row)

        views = QGroupBox("Views")
        vl = QVBoxLayout(views)
        self.views = QListWidget()
        self.views.setMinimumHeight(90)
        vl.addWidget(self.views)
        self.remove_button = button("Remove view", "vision_remove", "Drop the selected view (blurred or mis-detected)")
        self.remove_button.clicked.connect(guard(self._remove_selected))
        self.read_set_button = button(
            "Read set...",
            "vision_read_set",
            "Read a recorded hand-eye set in place of the views: a pose file (JSON of image and flange2base, a CSV of "
            "image and joints, cal_data.yaml) beside its images",
        )
        self.read_set_button.clicked.connect(guard(self._read_set_dialog))
        row = QHBoxLayout()
        row.addWidget(self.remove_button)
        row.addWidget(self.read_set_button)
        vl.addLayout(row)
        self.coverage = QLabel("No views yet.")
        self.coverage.setWordWrap(True)
        vl.addWidget(self.coverage)

        cal = QGroupBox("Calibrate")
        cl = QVBoxLayout(cal)
        self.calibrate_intrinsics_button = button(
            "Calibrate intrinsics", "vision_intrinsics", "fu, fv, cx, cy and k1 k2 p1 p2 k3 from the views (3 or more)"
        )
        self.calibrate_intrinsics_button.clicked.connect(guard(self.calibrate_intrinsics))
        self.calibrate_hand_eye_button = button(
            "Calibrate hand-eye",
            "vision_hand_eye",
            "The camera's mounting on the flange from the views and their robot poses (3 or more, 10 recommended)",
        )
        self.calibrate_hand_eye_button.clicked.connect(guard(self.calibrate_hand_eye))
        row = QHBoxLayout()
        row.addWidget(self.calibrate_intrinsics_button)
        row.addWidget(self.calibrate_hand_eye_button)
        cl.addLayout(row)
        self.result = QLabel("")
        self.result.setWordWrap(True)
        self.result.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        cl.addWidget(self.result)
        self.apply_intrinsics_button = button(
            "Apply intrinsics",
            "vision_apply_intrinsics",
            "Use the calibrated intrinsics for picking, solving and the virtual camera",
        )
        self.apply_intrinsics_button.clicked.connect(guard(self.apply_intrinsics))
        self.save_intrinsics_button = button(
            "Save...", "vision_save_intrinsics", "Save the intrinsics as OpenCV YAML or ROS camera_info"
        )
        self.save_intrinsics_button.clicked.connect(guard(self._save_intrinsics_dialog))
        self.apply_hand_eye_button = button(
            "Apply mounting",
            "vision_apply_hand_eye",
            "Use the measured camera mounting for the virtual camera, the solver's prior and the displacement",
        )
        self.apply_hand_eye_button.clicked.connect(guard(self.apply_hand_eye))
        self.save_hand_eye_button = button(
            "Save...", "vision_save_hand_eye", "Save cam2flange (xyz mm, rpy deg) with its 1-sigma as YAML"
        )
        self.save_hand_eye_button.clicked.connect(guard(self._save_hand_eye_dialog))
        for pair in (
            (self.apply_intrinsics_button, self.save_intrinsics_button),
            (self.apply_hand_eye_button, self.save_hand_eye_button),
        ):
            row = QHBoxLayout()
            row.addWidget(pair[0], 2)
            row.addWidget(pair[1], 1)
            cl.addLayout(row)

        layout = QVBoxLayout(self)
        layout.addWidget(board)
        layout.addWidget(views, 1)
        layout.addWidget(cal)
        self._spec_changed()

    # --- what the core holds, for tests and scripts ----------------------------------------------
    @property
    def capture(self):
        return self.vision.capture

    @property
    def intrinsics_result(self):
        return self.vision.intrinsics_result

    @property
    def hand_eye_result(self):
        return None if self.vision.mounting is None else self.vision.mounting.calibration

    @property
    def hand_eye_problems(self) -> list[str]:
        return [] if self.vision.mounting is None else self.vision.mounting.problems

    @property
    def _plan(self) -> list[np.ndarray]:
        return self.vision.plan

    # --- board ---------------------------------------------------------------------------------
    def _spec_changed(self) -> None:
        try:
            self.vision.set_board(self.spec.text())
        except ValueError:
            self.spec.setStyleSheet("color: #ff6060")
            raise
        self.spec.setStyleSheet("")
        self._refresh()

    def _show_board_toggled(self, on: bool) -> None:
        self.vision.show_board(None, on)

    def _next_pose(self) -> None:
        q, what = self.vision.next_board_pose()
        self._move_joints(q, what)

    # --- capturing -----------------------------------------------------------------------------
    def capture_view(self) -> None:
        """Detect the board in the current frame; keep it (with the joints) or say why not."""
        view = self.vision.capture_view()
        if isinstance(view, RejectedView):
            self.board_detected.emit(None, "")
        else:
            self.board_detected.emit(view.corners_px, f"{view.name}: {len(view.ids)} board corners")
        self._refresh()

    def _remove_selected(self) -> None:
        item = self.views.currentItem()
        if item is None or item.data(Qt.ItemDataRole.UserRole) is None:
            raise OperatorError("select an accepted view to remove")
        self.vision.remove_view(item.data(Qt.ItemDataRole.UserRole))
        self._refresh()

    def read_set(self, path) -> None:
        """Read a recorded hand-eye set (:meth:`CameraCalibrating.read_set`) in place of the views."""
        dialog = QProgressDialog("Reading the set's views...", "Cancel", 0, 1, self)
        dialog.setWindowTitle("Read set")
        dialog.setWindowModality(Qt.WindowModality.WindowModal)
        dialog.setMinimumDuration(500)  # a small set reads before it would show

        def progress(done: int, total: int) -> bool:
            dialog.setMaximum(total)
            dialog.setValue(done)
            dialog.setLabelText(f"Reading the set's views: {done} of {total} (finding the board in each)")
            QApplication.processEvents()
            return not dialog.wasCanceled()

        try:
            self.vision.read_set(path, progress)
        finally:
            dialog.close()
        self._intrinsics_text = self._hand_eye_text = ""
        self._show_results()
        self._refresh()

    def _read_set_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self, "Read a hand-eye set", "", "hand-eye sets (*.json *.csv *.yaml *.yml);;all files (*)"
        )
        if path:
            self.read_set(path)

    def _refresh(self) -> None:
        c = self.vision.capture
        if self.spec.text().strip() != str(c.spec):
            self.spec.setText(str(c.spec))  # a set read from files names its own board
        self.views.clear()
        lost = views_with_lost_corners([len(v.ids) for v in c.views])
        mounting = self.vision.mounting
        for k, v in enumerate(c.views):
            flag = f", lost corners ({len(v.ids)} where its neighbours have {lost[k]:.0f})" if k in lost else ""
            check = None if mounting is None else mounting.check_of(v.name)
            if check is not None:
                flag += f", {check.rms_px:.2f} px, {check.apart_mm:.1f} mm from the others"
            text = f"{v.name}: {len(v.ids)} corners" + ("" if c.has_robot_pose(k) else ", no robot pose") + flag
            self.views.addItem(("! " if check is not None and not check.agrees else "") + text)
            item = self.views.item(self.views.count() - 1)
            item.setData(Qt.ItemDataRole.UserRole, v.name)
            if check is not None and not check.agrees:
                item.setForeground(QColor(255, 170, 60))  # stands out: the operator looks at it, and may remove it
                item.setToolTip(check.why)
        for r in c.rejected:
            self.views.addItem(f"x {r.name}: {r.reason}")
        n = len(c.views)
        self.coverage.setText(
            f"{n} views, corners cover {100 * c.coverage():.0f} % of the image."
            + (
                ""
                if n >= 10
                else f" Add views with the board in every part of the image, tilted 20-40 deg ({max(0, 10 - n)} more "
                "for a stable calibration)."
            )
        )
        self.calibrate_intrinsics_button.setEnabled(n >= 3)
        self.calibrate_hand_eye_button.setEnabled(n >= 3 and all(c.has_robot_pose(k) for k in range(n)))
        has_intrinsics, has_mounting = self.vision.intrinsics_result is not None, self.vision.mounting is not None
        self.apply_intrinsics_button.setEnabled(has_intrinsics)
        self.save_intrinsics_button.setEnabled(has_intrinsics)
        self.apply_hand_eye_button.setEnabled(has_mounting)
        self.save_hand_eye_button.setEnabled(has_mounting)

    # --- calibrating ---------------------------------------------------------------------------
    def calibrate_intrinsics(self) -> None:
        with busy(self, "calibrating the intrinsics ..."):  # OpenCV's fit of every view: seconds on a real set
            r = self.vision.calibrate_intrinsics()
        i, s = r.intrinsics, r.std
        lines = [
            f"<b>Intrinsics</b> from {len(r.used)} views, RMS {r.rms_px:.3f} px",
            f"fu {i.fu:.2f} &plusmn; {s['fu']:.2f}, fv {i.fv:.2f} &plusmn; {s['fv']:.2f} px",
            f"cx {i.cx:.2f} &plusmn; {s['cx']:.2f}, cy {i.cy:.2f} &plusmn; {s['cy']:.2f} px",
            f"{' '.join(i.distortion_names)}: " + ", ".join(f"{v:+.4f}" for v in i.dist_coeffs),
        ]
        lines += [f"&bull; {a}" for a in r.advice]
        lines += [f"<span style='color:#e0a030'>check: {p}</span>" for p in self.vision.intrinsics_problems()]
        self._intrinsics_text = "<br>".join(lines)
        self._show_results()
        self._refresh()

    def _show_results(self) -> None:
        self.result.setText("<br><br>".join(t for t in (self._intrinsics_text, self._hand_eye_text) if t))

    def calibrate_hand_eye(self) -> None:
        with busy(self, "calibrating the camera's mounting ..."):
            m = self.vision.calibrate_mounting()
        r = m.calibration
        lines = [
            f"<b>Camera mounting</b> from {r.views} poses, RMS {r.rms_px:.3f} px",
            "position "
            + ", ".join(f"{v:.2f}" for v in r.cam2flange[:3, 3])
            + " mm (1-sigma "
            + ", ".join(f"{v:.3f}" for v in r.std_xyz_mm)
            + ")",
            f"differs from the model by {m.off_model_mm:.2f} mm and {m.off_model_deg:.3f} deg",
        ]
        lines += [f"<span style='color:#e0a030'>warning: {w}</span>" for w in m.problems]
        self._hand_eye_text = "<br>".join(lines)
        self._show_results()
        self._refresh()

    def _confirmed(self, what: str, problems: list[str]) -> list[str] | None:
        """The problems the operator accepted (none to accept: an empty list); ``None`` when they declined."""
        if not problems:
            return []
        text = "\n".join(
            [f"The {what} failed its checks:", *[f"- {p}" for p in problems], "", f"Use this {what} anyway?"]
        )
        if not ask(self, f"Apply a {what} that failed its checks?", text, "Apply anyway"):
            self._say(f"{what} not applied")
            return None
        return list(problems)

    def apply_intrinsics(self) -> None:
        if self.vision.intrinsics_result is None:
            raise OperatorError("calibrate the intrinsics first")
        accepted = self._confirmed("intrinsics calibration", self.vision.intrinsics_problems())
        if accepted is not None:
            self.vision.apply_calibrated_intrinsics(accepted)

    def apply_hand_eye(self) -> None:
        if self.vision.mounting is None:
            raise OperatorError("calibrate the hand-eye first")
        accepted = self._confirmed("camera mounting", self.vision.mounting.problems)
        if accepted is not None:
            self.vision.apply_calibrated_mounting(accepted)

    def save_intrinsics(self, path, fmt: str = "opencv") -> None:
        self.vision.save_intrinsics(path, fmt)

    def save_hand_eye(self, path) -> None:
        self.vision.save_mounting(path)

    def _save_intrinsics_dialog(self) -> None:
        path, chosen = QFileDialog.getSaveFileName(
            self, "Save intrinsics", "camera.yaml", "OpenCV YAML (*.yaml *.yml);;ROS camera_info (*.yaml *.yml)"
        )
        if path:
            self.save_intrinsics(path, "ros" if chosen.startswith("ROS") else "opencv")

    def _save_hand_eye_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self, "Save camera mounting", "hand_eye.yaml", "hand-eye YAML (*.yaml *.yml)"
        )
        if path:
            self.save_hand_eye(path)
