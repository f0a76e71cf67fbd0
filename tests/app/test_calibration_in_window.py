"""The whole calibration through the real window: the controller simulator as a child process,
the simulated camera on its worker thread, and mouse clicks on the panes' widgets."""

from calib_core.calibration.commands import SetPixel
from calib_core.calibration.commands import AddPoint3D
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtWidgets import QApplication

from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference
from calib_core.solver import SolveStatus
from tests.app.windows import (
    click_image,
    confirm_move_if_asked,
    go_to_task,
    pick_features,
    pick_pair,
    wait_for_settled_frame,
)

OUTPUT = Path(__file__).resolve().parents[1] / "output"
FEATURES = [
    "plate_top_left",
    "plate_top_right",
    "plate_bottom_right",
    "plate_bottom_left",
    "boss_top_left",
    "boss_bottom_right",
]


def test_operator_calibrates_the_task_location_by_point_and_click(qtbot, window):
    win = window
    wb = win.workbench
    bed = wb.site.bed  # the truth, for the operator's eyes and the score
    go_to_task(qtbot, win)
    fixture = wb.workcell.component("oru_1_fixture")
    model_cam = wb.model_cam2world()
    true_cam = bed.true_cam2world(wb.joints_deg)
    for k, name in enumerate(FEATURES, start=1):
        p_world = apply(fixture.item2world, fixture.features[name])
        uv_model = project(apply(invert(model_cam), p_world[None]), win.virtual.intrinsics, distort=False)[0]
        click_image(qtbot, win.virtual.view, *uv_model)
        pair = wb.session.pairs.pending()
        assert pair is not None and pair.feature == name, f"pick {k}: {win.virtual.info.text()}"
        # The operator looks at the camera image and clicks the same corner: here the truth tells where it is.
        uv_true = project(apply(invert(true_cam), p_world[None]), wb.intrinsics)[0]
        # Sub-pixel refinement finds corners; the operator turns it off for the centre of a round boss.
        win.camera.subpixel.setChecked(name.startswith("plate"))
        click_image(qtbot, win.camera.view, *uv_true, zoom=4.0)
        picked = wb.session.pairs.get(pair.number).pixel
        assert picked is not None
        assert np.linalg.norm(np.array(picked) - uv_true) < 1.0
        qtbot.keyClick(win, Qt.Key.Key_Return, Qt.KeyboardModifier.ControlModifier)
    assert len(wb.session.pairs.usable()) == len(FEATURES)
    assert win.table.rowCount() == len(FEATURES)
    assert win.commands.calibrate.isEnabled()
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    result = wb.session.result.estimate
    assert result is not None and result.solution.status is SolveStatus.OK, win.results.status.text()
    assert result.solution.rms_px < 1.0
    d_true, r_true = pose_difference(bed.true_robot.fk(wb.joints_deg), bed.model_robot.fk(wb.joints_deg))
    assert np.linalg.norm(result.displacement_mm - d_true) < 1.0
    assert "OK" in win.results.verdict.text()
    # The CAD edges from the solved pose follow the points (next turn of the event loop) and lie on the
    # plate's outline: the overlay is opaque at the projected corners' neighbourhood.
    qtbot.waitUntil(lambda: win.camera.edges_drawn > 0, timeout=5_000)
    edges = win.camera.view.overlay.image
    assert edges is not None and edges.shape[:2] == (wb.intrinsics.height, wb.intrinsics.width)
    for name in ("plate_top_left", "plate_bottom_right"):
        u, v = np.round(
            project(apply(invert(true_cam), apply(fixture.item2world, fixture.features[name])[None]), wb.intrinsics)[0]
        ).astype(int)
        assert edges[v - 3 : v + 4, u - 3 : u + 4, 3].max() > 100, name
    # nothing drawn inside the flat plate face, between the bosses and the pin
    u, v = np.round(
        project(apply(invert(true_cam), apply(fixture.item2world, np.array([0.0, -25.0, 25.0]))[None]), wb.intrinsics)[
            0
        ]
    ).astype(int)
    assert edges[v - 3 : v + 4, u - 3 : u + 4, 3].max() == 0
    OUTPUT.mkdir(exist_ok=True)
    win.grab().save(str(OUTPUT / "window_after_calibration.png"))

    # The solve is an edit like the picks: Undo takes it (and its edges) back, Redo shows the same answer.
    assert win.actions.undo_action.text() == f"&Undo Calibrate ({len(FEATURES)} pairs)"
    qtbot.mouseClick(win.commands.undo, Qt.MouseButton.LeftButton)
    assert wb.session.result.estimate is None and win.camera.view.overlay.image is None
    assert "OK" not in win.results.verdict.text()
    drawn = win.camera.edges_drawn
    qtbot.mouseClick(win.commands.redo, Qt.MouseButton.LeftButton)
    assert wb.session.result.estimate is result and "OK" in win.results.verdict.text()
    qtbot.waitUntil(lambda: win.camera.edges_drawn > drawn, timeout=5_000)

    # Store the correction, undo it, redo it.
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    assert wb.session.corrections.latest(wb.task.name) is not None
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert wb.session.corrections.latest(wb.task.name) is None
    qtbot.mouseClick(win.commands.redo, Qt.MouseButton.LeftButton)
    assert wb.session.corrections.latest(wb.task.name) is not None

    # Execute the task with its correction: the real tool ends close to the planned location.
    qtbot.mouseClick(win.commands.go_corrected, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    corrected = wb.session.corrections.corrected_target(wb.task.name, wb.task.tcp2base)
    qtbot.waitUntil(
        lambda: np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), corrected)[0]) < 0.01, timeout=20_000
    )
    miss = np.linalg.norm(pose_difference(bed.true_robot.fk(wb.joints_deg), wb.task.tcp2base)[0])
    miss_uncorrected = np.linalg.norm(d_true)
    assert miss < 0.5 and miss < miss_uncorrected / 10


def test_mistakes_become_messages_not_crashes(qtbot, window):
    win = window
    wb = win.workbench
    # An image click before any model pick.
    import time

    from calib_core.connectors.frame import Frame

    wait_for_settled_frame(qtbot, win)  # Hold holds only a frame taken with the robot settled
    win.camera.freeze.setChecked(True)  # the operator froze this (black) frame to pick on
    assert wb.observations.still is not None
    win.camera.show_frame(Frame(np.zeros((480, 640, 3), np.uint8), 0, time.monotonic()))
    click_image(qtbot, win.camera.view, 100, 100)
    assert "pick the point on the model" in win.results.status.text()
    # Calibrate with no pairs: the button is disabled, the shortcut explains.
    assert not win.commands.calibrate.isEnabled()
    qtbot.keyClick(win, Qt.Key.Key_F5)
    assert "complete pairs; calibrating needs 3" in win.results.status.text()
    # Going to a corrected location that has no correction.
    qtbot.mouseClick(win.commands.go_corrected, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    assert "no stored correction" in win.results.status.text()
    # Accept with nothing picked, then with only the 3D point.
    qtbot.mouseClick(win.commands.accept, Qt.MouseButton.LeftButton)
    assert "nothing to accept" in win.results.status.text()
    wb.session.undo.push(
        AddPoint3D(wb.session.pairs, "oru_1_fixture", "pin_tip", (1127.5, -421.8, 1367.7), target=wb.session.target)
    )
    qtbot.mouseClick(win.commands.accept, Qt.MouseButton.LeftButton)
    assert "has no point on the camera image yet" in win.results.status.text()
    # A click outside the image (zoomed out, in the margin): nothing picked, the pair still waits.
    win.camera.view.set_zoom(0.5)
    qtbot.mouseClick(win.camera.view, Qt.MouseButton.LeftButton, pos=QPoint(3, 3))
    assert "outside the camera image" in win.results.status.text()
    assert wb.session.pairs.pending() is not None and len(wb.session.pairs) == 1
    win.camera.view.reset_view()
    assert win.isVisible()


def test_a_degenerate_point_set_is_explained_and_loses_no_pair(qtbot, window):
    win, wb = window, window.workbench
    fixture = wb.workcell.component("oru_1_fixture")
    # Four points on one straight line of the plate: no pose follows from them.
    wait_for_settled_frame(qtbot, win)
    for k, y in enumerate((-60.0, -20.0, 20.0, 60.0)):
        pick_pair(
            wb, "oru_1_fixture", None, apply(fixture.item2world, np.array([0.0, y, 0.0])), (100.0 + 50 * k, 200.0)
        )
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    text = win.results.status.text().lower()
    assert "line" in text or "degenerate" in text or "collinear" in text, text
    assert len(wb.session.pairs.usable()) == 4


def test_a_camera_that_stops_and_a_link_that_drops_are_reported(qtbot, window, tmp_path):
    import cv2

    from calib_core.video.folder_source import ImageFolderSource

    win, wb = window, window.workbench
    wb.session.undo.push(
        AddPoint3D(wb.session.pairs, "oru_1_fixture", "pin_tip", (1127.5, -421.8, 1367.7), target=wb.session.target)
    )
    wb.session.undo.push(SetPixel(wb.session.pairs, None, (320.0, 240.0)))
    # The camera: a folder of two images, not looped, ends; the window says so and keeps the last frame.
    for k in range(2):
        cv2.imwrite(str(tmp_path / f"frame_{k}.png"), np.full((480, 640, 3), 60 + 40 * k, np.uint8))
    win.worker.stop()
    win.start_camera(lambda: ImageFolderSource(tmp_path, loop=False, fps=20.0))
    qtbot.waitUntil(lambda: "end of stream" in win.results.status.text(), timeout=10_000)
    assert win.camera.last_frame is not None
    win._update_status()
    fps = win.status_line.fps_label
    qtbot.waitUntil(lambda: (win._update_status(), "no frame for" in fps.text())[1], timeout=10_000)
    # The link shows its measured delay (the handshake timed the round trip; a near controller: milliseconds).
    qtbot.waitUntil(lambda: (win._update_status(), "delay" in win.status_line.link_label.text())[1], timeout=10_000)
    assert wb.link.delay_s is not None and wb.link.delay_s < 1.0
    # the sample rate by the controller's stamps: the 50 Hz the link asks for (arrivals per second of ours showed
    # 182 Hz on a far link's bursts)
    qtbot.waitUntil(lambda: (win._update_status(), " Hz, " in win.status_line.link_label.text())[1], timeout=10_000)
    hz = float(win.status_line.link_label.text().split(" Hz, ")[0].split(", ")[-1])
    assert 40.0 <= hz <= 60.0, win.status_line.link_label.text()
    # redrawn again at once, the line keeps the rate counted over a second of the controller's clock (counted over the
    # instant between two redraws it was gone, or one sample more or less read as 62 Hz)
    for _ in range(5):
        win._update_status()
        again = win.status_line.link_label.text()
        assert " Hz, " in again and 40.0 <= float(again.split(" Hz, ")[0].split(", ")[-1]) <= 60.0, again
    # The link: the controller process dies; the state shows it and no pair is lost.
    wb.site.process.process.kill()
    # (and its pty with it: the path left behind may soon lead to another program's pty on a busy machine)
    wb.site.process.link_path.unlink(missing_ok=True)
    qtbot.waitUntil(lambda: wb.link.state.value != "up", timeout=10_000)
    qtbot.waitUntil(lambda: "up" not in win.status_line.link_label.text().split(",")[0], timeout=5_000)
    qtbot.mouseClick(win.commands.go_task, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    assert "nothing was sent" in win.results.status.text()  # the link's reason, not "moving to ..."
    assert len(wb.session.pairs) == 1 and wb.session.pairs.pairs()[0].pixel == (320.0, 240.0)
    assert win.isVisible()


def test_the_approach_is_edited_undone_and_the_overview_pans(qtbot, window):
    win, wb = window, window.workbench
    task = wb.task
    assert win.commands.approach.value() == pytest.approx(task.approach_mm)
    win.commands.approach.setValue(150.0)
    assert wb.workcell.task(task.name).approach_mm == 150.0 and wb.task.approach_mm == 150.0
    np.testing.assert_allclose(
        wb.task.approach2base[:3, 3], (task.tcp2base @ np.array([0, 0, -150.0, 1]))[:3], atol=1e-9
    )
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert wb.workcell.task(task.name).approach_mm == task.approach_mm
    assert win.commands.approach.value() == pytest.approx(task.approach_mm)
    # Right-drag pans the overview: the point looked at moves, the view is redrawn.
    target, redraws = win.overview.target.copy(), win.overview.redraws
    view = win.overview.view
    qtbot.mousePress(view, Qt.MouseButton.RightButton, pos=QPoint(100, 100))
    qtbot.mouseMove(view, QPoint(160, 130))
    qtbot.mouseRelease(view, Qt.MouseButton.RightButton, pos=QPoint(160, 130))
    assert np.linalg.norm(win.overview.target - target) > 10.0 and win.overview.redraws > redraws


def test_ambiguous_solve_shows_ghosts_and_the_operator_chooses(qtbot, window):
    win = window
    wb = win.workbench
    go_to_task(qtbot, win)
    fixture = wb.workcell.component("oru_1_fixture")
    true_cam = wb.site.bed.true_cam2world(wb.joints_deg)
    for name in ("plate_top_left", "plate_top_right", "pin_tip"):  # three pairs: P3P has several exact poses
        p = apply(fixture.item2world, fixture.features[name])
        pick_pair(wb, "oru_1_fixture", name, p, project(apply(invert(true_cam), p[None]), wb.intrinsics)[0])
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    solution = wb.session.result.estimate.solution
    if solution.status is not SolveStatus.AMBIGUOUS:
        pytest.skip("this configuration has a single P3P root")
    ghosts = [p for p in win.camera.view.overlay.points if p[2].startswith("s")]
    assert ghosts and "poses fit" in win.camera.view.overlay.text
    button = win.results.findChild(type(win.commands.calibrate), "candidate_1")
    assert button is not None
    before = wb.session.result.estimate.cam2world_measured.copy()
    qtbot.mouseClick(button, Qt.MouseButton.LeftButton)
    assert wb.session.result.chosen_candidate == 1
    assert not np.allclose(wb.session.result.estimate.cam2world_measured, before)
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert wb.session.result.chosen_candidate == 0


def test_camera_pane_loupe_and_crosshair_are_drawn(qtbot, window):
    win = window
    view = win.camera.view
    image = np.zeros((480, 640, 3), np.uint8)
    image[240, 320] = (255, 0, 0)  # one red pixel to find in the loupe
    # No camera frame may replace this image before the grab: the worker stops (its thread joined) and
    # the frames it had already queued to the GUI thread are delivered first. (Freeze cannot hold them
    # off: it holds only a frame taken after the robot settled, which a young window may not have.)
    win.worker.stop()
    assert win.worker.isFinished()
    QApplication.processEvents()
    view.set_image(image)
    x, y = view.image_to_widget(320, 240)
    qtbot.mouseMove(view, QPoint(int(round(x)), int(round(y))))
    view._mouse = QPointF(x, y)
    view.underMouse = lambda: True
    shot = view.grab().toImage()
    # The loupe sits in the bottom corner away from the cursor and shows the red pixel magnified.
    reds = [
        (i, j)
        for i in range(shot.width())
        for j in range(shot.height() - 160, shot.height())
        if shot.pixelColor(i, j).red() > 200 and shot.pixelColor(i, j).green() < 60
    ]
    assert len(reds) > 20


def test_simulate_animates_the_model_in_the_overview_only(qtbot, window):
    win, wb = window, window.workbench
    q_before, redraws = wb.joints_deg.copy(), win.overview.redraws
    qtbot.mouseClick(win.commands.animate, Qt.MouseButton.LeftButton)
    assert "joints within limits" in win.commands.sim_status.text() or "of its limit" in win.commands.sim_status.text()
    qtbot.waitUntil(lambda: win.overview.redraws >= redraws + 20, timeout=10_000)  # 31 steps at 40 ms
    assert np.allclose(wb.joints_deg, q_before)  # the robot did not move
    qtbot.waitUntil(lambda: not win.overview._path_timer.isActive(), timeout=10_000)
    assert win.overview._shown_joints is None  # back to the real joints


def test_a_refused_move_is_shown_and_ctrl_q_stops_the_simulator(qtbot, window):
    win, wb = window, window.workbench
    q = wb.joints_deg.copy()
    q[5] = wb.robot.upper_limits_deg[5] + 10.0
    win.report(lambda: wb.moves.move_joints(q, "a pose past the wrist's limit"))()
    assert "outside its limits" in win.results.status.text()  # the core refuses it: nothing is sent
    # A model whose limits are wider than the controller's: the controller refuses the move, and the window says so.
    wb.robot.model.upperPositionLimit[5] += np.radians(20.0)
    win.actions.move(lambda confirmed: wb.moves.move_joints(q, "a pose past the wrist's limit", confirmed=confirmed))
    confirm_move_if_asked(qtbot, win)
    qtbot.waitUntil(lambda: "LIMIT" in win.results.status.text(), timeout=10_000)
    assert "move to a pose past the wrist's limit failed" in win.results.status.text()
    assert wb.motion.motion.value == "refused" and "refused" in win.status_line.motion_label.text()
    process = wb.site.process
    assert process.running
    from PySide6.QtGui import QKeySequence

    quit_action = next(a for a in win.files.menu.actions() if a.shortcut() == QKeySequence("Ctrl+Q"))
    quit_action.trigger()
    qtbot.waitUntil(lambda: not process.running, timeout=10_000)
    assert not win.isVisible()


def test_a_message_about_an_earlier_step_goes_when_a_result_comes(qtbot, window):
    """F5 with no pairs says calibrating needs 3; after four picks and Calibrate the verdict is OK and that message is
    gone (it once stayed under the OK verdict, as "the last solve failed" did)."""
    win, wb = window, window.workbench
    go_to_task(qtbot, win)
    qtbot.keyClick(win, Qt.Key.Key_F5)
    assert "calibrating needs 3" in win.results.status.text()
    pick_features(qtbot, win, ["plate_bottom_left", "plate_bottom_right", "pin_tip", "boss_top_left"])
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: wb.session.result.estimate is not None, timeout=30_000)
    assert "OK" in win.results.verdict.text(), win.results.verdict.text()
    assert "calibrating needs" not in win.results.status.text()
