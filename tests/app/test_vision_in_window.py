"""The Vision mode through the real window: the board put up in the simulated cell, the robot stepped
through viewing poses over the controller link, views captured from the live camera, the intrinsics
and the camera's mounting calibrated against the test bed's truth, applied and saved."""

import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from PySide6.QtCore import Qt

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.frames import pose_difference
from tests.app.recorded_sets import recorded_set
from tests.app.windows import confirm_move_if_asked
from videocal_sim.true_robot import RobotErrors

OUTPUT = Path(__file__).resolve().parents[1] / "output"


@pytest.fixture
def window(live_window):
    typical = RobotErrors.typical(0)
    # The robot's kinematics exact, the camera mounting not: what a hand-eye calibration can find.
    return live_window(RobotErrors(hand_eye_xyz_mm=typical.hand_eye_xyz_mm, hand_eye_rpy_deg=typical.hand_eye_rpy_deg))


def _fresh_still_frame(qtbot, win, after_s: float | None = None):
    """Wait until the camera shows a frame the core accepts: taken after the robot had settled (and after
    ``after_s``, the monotonic clock's seconds the frames are stamped in, when given)."""
    wb = win.workbench

    def fresh() -> bool:
        frame = win.camera.last_frame
        if frame is None or (after_s is not None and frame.t_host_s <= after_s):
            return False
        return wb.observations.stillness(frame).settled

    qtbot.waitUntil(fresh, timeout=10_000)


def _visit_board_pose(qtbot, win, k: int) -> None:
    """Next board pose (the k-th of the plan), wait for the controller's done and a frame taken at rest."""
    qtbot.mouseClick(win.vision.next_pose, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)  # a large joint change waits for Move in the overview
    target = win.vision._plan[k]
    try:
        qtbot.waitUntil(lambda: win.workbench.motion.motion.value == "arrived", timeout=30_000)
    except Exception:
        raise AssertionError(
            f"board pose {k + 1}: {win.workbench.motion.text}; {win.results.status.text()}; "
            f"{win.overview.preview_text.text()}"
        ) from None
    # the controller's done can be read before its last samples on the way in (0.0013 deg short once, under load):
    # the samples that follow must reach the target
    qtbot.waitUntil(lambda: np.max(np.abs(win.workbench.joints_deg - target)) < 1e-3, timeout=5_000)
    # and a frame taken since: under load the last frame shown can still be one from before the move, taken with the
    # robot at rest at its start (settled, and without the board: "no board found" once)
    _fresh_still_frame(qtbot, win, after_s=time.monotonic())


def test_board_views_to_intrinsics_and_mounting(qtbot, window, tmp_path, monkeypatch):
    win, wb = window, window.workbench
    vision = win.vision
    win.commands.setCurrentIndex(next(i for i in range(win.commands.count()) if win.commands.tabText(i) == "Vision"))
    assert not vision.calibrate_intrinsics_button.isEnabled()

    # At home the camera does not see the board: the view is rejected and said why.
    _fresh_still_frame(qtbot, win)
    qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
    assert len(vision.capture.rejected) == 1 and "no board found" in win.statusBar().currentMessage()

    vision.show_board.setChecked(True)
    # 12 poses of the plan (those of 16 candidates that see the board on collision-free paths): a stable set
    for k in range(12):
        _visit_board_pose(qtbot, win, k)
        qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
        assert len(vision.capture.views) == k + 1, vision.views.item(vision.views.count() - 1).text()
        if k == 0:
            OUTPUT.mkdir(exist_ok=True)
            win.grab().save(str(OUTPUT / "window_vision.png"))
            # the detection is drawn over the camera image
            assert len(win.camera.view.overlay.points) >= 20 and "board corners" in win.camera.view.overlay.text
    assert vision.calibrate_intrinsics_button.isEnabled() and vision.calibrate_hand_eye_button.isEnabled()
    assert vision.views.count() == 13 and vision.views.item(12).text().startswith("x view_01")

    # Intrinsics against the test bed's lens; while OpenCV fits them the window says so and shows the wait cursor
    from PySide6.QtWidgets import QApplication

    during = []
    fit = vision.vision.calibrate_intrinsics

    def watched():
        cursor = QApplication.overrideCursor()
        during.append((win.statusBar().currentMessage(), cursor.shape() if cursor is not None else None))
        return fit()

    monkeypatch.setattr(vision.vision, "calibrate_intrinsics", watched)
    qtbot.mouseClick(vision.calibrate_intrinsics_button, Qt.MouseButton.LeftButton)
    assert during == [("calibrating the intrinsics ...", Qt.CursorShape.WaitCursor)]
    assert QApplication.overrideCursor() is None and "calibrating" not in win.statusBar().currentMessage()
    got, truth = vision.intrinsics_result.intrinsics, wb.site.bed.intrinsics
    assert abs(got.fu / truth.fu - 1) < 0.005 and abs(got.fv / truth.fv - 1) < 0.005
    assert abs(got.cx - truth.cx) < 2.0 and abs(got.cy - truth.cy) < 2.0
    assert vision.intrinsics_result.rms_px < 0.3 and "Intrinsics" in vision.result.text()

    # The camera's mounting against the true one (the model's is off by ~1 mm and ~0.2 deg).
    qtbot.mouseClick(vision.calibrate_hand_eye_button, Qt.MouseButton.LeftButton)
    true_robot = wb.site.bed.true_robot.robot
    true_cam2flange = np.linalg.inv(true_robot.frame_placement("flange")) @ true_robot.frame_placement("camera")
    model_cam2flange = np.linalg.inv(wb.robot.frame_placement("flange")) @ wb.robot.frame_placement("camera")
    d_model, r_model = pose_difference(model_cam2flange, true_cam2flange)
    d, r = pose_difference(vision.hand_eye_result.cam2flange, true_cam2flange)
    # 12 views at 640 x 480 with the intrinsics calibrated from the same views: a few tenths of a mm remain
    assert np.linalg.norm(d) < 0.5 * np.linalg.norm(d_model) and np.linalg.norm(r) < 0.5 * np.linalg.norm(r_model)
    assert "Camera mounting" in vision.result.text()

    # Apply both: the window's model now uses them, the virtual camera redraws.
    renders = win.virtual.renders
    qtbot.mouseClick(vision.apply_hand_eye_button, Qt.MouseButton.LeftButton)
    applied = np.linalg.inv(wb.robot.frame_placement("flange")) @ wb.robot.frame_placement("camera")
    assert np.allclose(applied, vision.hand_eye_result.cam2flange)
    assert win.virtual.renders > renders
    qtbot.mouseClick(vision.apply_intrinsics_button, Qt.MouseButton.LeftButton)
    assert wb.intrinsics == got and win.virtual.intrinsics.fu == pytest.approx(
        got.fu * win.virtual.intrinsics.width / got.width
    )

    # Saved files read back.
    vision.save_intrinsics(tmp_path / "camera.yaml")
    assert load_intrinsics(tmp_path / "camera.yaml").fu == pytest.approx(got.fu)
    vision.save_hand_eye(tmp_path / "hand_eye.yaml")
    doc = yaml.safe_load((tmp_path / "hand_eye.yaml").read_text())
    assert doc["units"] == {"length": "mm", "angle": "deg"} and doc["poses"] == 12
    wb.apply_hand_eye_file(tmp_path / "hand_eye.yaml")
    again = np.linalg.inv(wb.robot.frame_placement("flange")) @ wb.robot.frame_placement("camera")
    assert np.linalg.norm(pose_difference(again, vision.hand_eye_result.cam2flange)[0]) < 1e-3


def test_bad_vision_input_gives_messages(qtbot, window):
    win, wb = window, window.workbench
    vision = win.vision
    vision.spec.setText("charuco:nonsense")
    vision.spec.editingFinished.emit()
    assert "board spec" in win.results.status.text() and vision.capture is not None
    # Removing with nothing selected.
    qtbot.mouseClick(vision.remove_button, Qt.MouseButton.LeftButton)
    assert "select an accepted view" in win.results.status.text()
    # Capturing while the robot moves: refused, nothing kept.
    vision.show_board.setChecked(True)
    qtbot.mouseClick(vision.next_pose, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    start = wb.joints_deg.copy()
    qtbot.waitUntil(lambda: np.max(np.abs(wb.joints_deg - start)) > 0.5, timeout=10_000)

    # the frame the capture takes (the newest usable one), taken after the move was sent and unsettled by the core's
    # rule: what the capture applies (under load the newest may still predate the move, a refusal of its own)
    def moving_frame() -> bool:
        frame = wb.observations.newest_usable()
        sent_s = wb.arm.last_move_sent_s
        return (
            frame is not None
            and sent_s is not None
            and frame.t_host_s > sent_s
            and not wb.observations.stillness(frame).settled
        )

    qtbot.waitUntil(moving_frame, timeout=5_000)
    qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
    assert "the robot was moving" in win.results.status.text() and "deg/s" in win.results.status.text()
    assert not vision.capture.views and not vision.capture.rejected


def test_board_views_captured_from_a_recording_keep_their_recorded_joints(qtbot, window, tmp_path):
    """Record the board at a few poses, then capture the views from the replayed frames: each view takes
    the joints recorded with its frame, so the hand-eye data comes out of a recording as well as live."""
    from calib_core.recording.playback import RecordingPlayback
    from calib_core.recording.reader import read_recording

    win, wb = window, window.workbench
    vision = win.vision
    vision.show_board.setChecked(True)
    win.files.start_recording(tmp_path / "board.mcap")
    for k in range(4):
        _visit_board_pose(qtbot, win, k)
        # Frames at rest into the recording: 0.3 s of camera time past the first still frame (the
        # replay below seeks 0.15 s past the settle time), however slow the machine runs.
        still = win.camera.last_frame.t_host_s
        qtbot.waitUntil(lambda: win.camera.last_frame.t_host_s >= still + 0.3, timeout=10_000)
    win.files.stop_recording()
    plan = vision._plan[:4]
    playback = RecordingPlayback(read_recording(tmp_path / "board.mcap"))
    win.files.open_recording(tmp_path / "board.mcap")
    assert wb.frames.replaying
    messages = []
    for q in plan:
        # just before the robot left this pose: frames and joints at rest for 0.3 s and more by then,
        # however sparse the frames a loaded machine recorded
        # (the joints are recorded sparsely at rest: the first sample away from the pose is the departure)
        at = [t for t, rq in zip(playback.joint_times_s, playback.joints_deg) if np.max(np.abs(rq - q)) < 1e-3]
        left = [
            t
            for t, rq in zip(playback.joint_times_s, playback.joints_deg)
            if t > max(at) and np.max(np.abs(rq - q)) >= 1e-3
        ]
        win.replay.seek((min(left) if left else max(at)) - 0.05)
        qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
        messages.append(win.results.status.text())
    assert len(vision.capture.views) == 4, (
        [vision.views.item(i).text() for i in range(vision.views.count())],
        messages,
    )
    for recorded, q in zip(vision.capture.joints_deg, plan):
        assert np.max(np.abs(recorded - q)) < 1e-3


def test_a_hand_eye_that_fails_its_checks_is_applied_only_when_confirmed(qtbot, live_window):
    """A robot with its typical kinematic errors: the views disagree (hand-eye takes the kinematics as
    exact), so Apply mounting asks first; the intrinsics result stays on screen under the hand-eye."""
    from tests.app.windows import answer_next_question as _answer

    win = live_window(RobotErrors.typical(0))
    wb, vision = win.workbench, win.vision
    vision.show_board.setChecked(True)
    for k in range(5):
        _visit_board_pose(qtbot, win, k)
        qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(vision.calibrate_intrinsics_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(vision.calibrate_hand_eye_button, Qt.MouseButton.LeftButton)
    assert "Intrinsics" in vision.result.text() and "Camera mounting" in vision.result.text()
    assert vision.hand_eye_problems and "do not agree" in " ".join(vision.hand_eye_problems)
    before = wb.robot.frame_placement("camera").copy()
    asked = _answer(qtbot, "Cancel")
    qtbot.mouseClick(vision.apply_hand_eye_button, Qt.MouseButton.LeftButton)
    assert asked and "failed its checks" in asked[0] and np.array_equal(wb.robot.frame_placement("camera"), before)
    events = []
    wb.log.event.connect(lambda kind, detail: events.append(kind))
    asked = _answer(qtbot, "Apply anyway")
    qtbot.mouseClick(vision.apply_hand_eye_button, Qt.MouseButton.LeftButton)
    assert (
        asked and not np.array_equal(wb.robot.frame_placement("camera"), before) and "vision_result_confirmed" in events
    )


def test_captures_while_the_robot_moves_take_nothing(qtbot, window):
    """Four captures while the robot moved to the next board pose were all accepted, each a copy
    of the frame from before the move (the still held for picking); coverage stayed while the count rose."""
    win, wb = window, window.workbench
    vision = win.vision
    vision.show_board.setChecked(True)
    _visit_board_pose(qtbot, win, 0)
    qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
    assert len(vision.capture.views) == 1
    wb.frames.hold_frame()  # a still held for picking, from before the move: the old code captured it again and again
    qtbot.mouseClick(vision.next_pose, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    refusals = []
    while wb.motion.motion.value == "moving":
        qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
        refusals.append(win.results.status.text())
        qtbot.wait(150)
    # (how many tries fit in the move depends on the machine's load: at least one, all refused)
    assert len(refusals) >= 1 and len(vision.capture.views) == 1, refusals
    assert all("before the last move" in r or "cannot be used" in r for r in refusals), refusals
    _fresh_still_frame(qtbot, win)
    qtbot.waitUntil(
        lambda: (
            wb.observations.latest.t_host_s > wb.arm.last_move_sent_s
            and wb.observations.stillness(wb.observations.newest_usable()).settled
        ),
        timeout=10_000,
    )
    qtbot.mouseClick(vision.capture_button, Qt.MouseButton.LeftButton)
    assert len(vision.capture.views) == 2


def test_a_recorded_set_is_read_and_its_odd_view_shown_and_dropped(qtbot, window, tmp_path):
    """Read set... takes a recorded set (images and their flange poses) in place of the views; after Calibrate
    hand-eye each view shows its residual and its distance from the others, the view whose pose was recorded 15 mm
    off stands out (marked, with why), and once it is removed the calibration again has no view that stands out."""
    from tests.app.windows import answer_file_dialog

    win = window
    path = recorded_set(tmp_path / "set", moved_view=3, moved_mm=15.0)
    asked = answer_file_dialog(path)
    qtbot.mouseClick(win.vision.read_set_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: len(win.vision.capture.views) == 10, timeout=30_000)
    assert asked == ["Read a hand-eye set"]
    assert all(win.vision.capture.has_robot_pose(k) for k in range(10))
    qtbot.mouseClick(win.vision.calibrate_intrinsics_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(win.vision.calibrate_hand_eye_button, Qt.MouseButton.LeftButton)
    rows = [win.vision.views.item(k) for k in range(win.vision.views.count())]
    odd = [r for r in rows if r.text().startswith("! ")]
    moved = win.vision.capture.views[3].name
    assert [r.data(Qt.ItemDataRole.UserRole) for r in odd] == [moved], [r.text() for r in rows]
    assert "mm from the others' mean" in odd[0].toolTip() and " px, " in odd[0].text()
    win.vision.views.setCurrentItem(odd[0])
    qtbot.mouseClick(win.vision.remove_button, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(win.vision.calibrate_hand_eye_button, Qt.MouseButton.LeftButton)
    rows = [win.vision.views.item(k).text() for k in range(win.vision.views.count())]
    assert len(rows) == 9 and not any(r.startswith("! ") for r in rows), rows
    assert win.vision.hand_eye_result.views == 9
