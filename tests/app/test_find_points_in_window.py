"""Find points through the real window: F6 on the held frame at the task location, the list of
proposals, one unchecked, Accept checked: pairs in one undo step, drawn, solved."""

from pathlib import Path

import numpy as np
from PySide6.QtCore import Qt

from calib_core.frames import pose_difference
from tests.app.windows import go_to_task

OUTPUT = Path(__file__).resolve().parents[1] / "output"


def test_f6_proposes_points_and_accept_checked_adds_them_in_one_undo_step(qtbot, window):
    win = window
    wb = win.workbench
    go_to_task(qtbot, win)
    qtbot.keyClick(win, Qt.Key.Key_F6)
    qtbot.waitUntil(lambda: win.finder.dialog is not None and win.finder.dialog.isVisible(), timeout=20_000)
    dialog = win.finder.dialog
    result = dialog.found.result
    assert result.found, result.message
    assert dialog.table.rowCount() == len(result.proposals) >= 4
    assert any(p[3].name() == "#50c8ff" for p in win.camera.view.overlay.points)  # the proposals are drawn
    OUTPUT.mkdir(exist_ok=True)
    win.grab().save(str(OUTPUT / "window_find_points.png"))
    dialog.grab().save(str(OUTPUT / "find_points_dialog.png"))
    dialog.table.item(0, 0).setCheckState(Qt.CheckState.Unchecked)  # the operator rejects one
    kept = dialog.checked_features()
    qtbot.mouseClick(dialog.accept_button, Qt.MouseButton.LeftButton)
    assert not dialog.isVisible() and [p.feature for p in wb.session.pairs] == kept
    assert win.table.rowCount() == len(kept)
    assert not any(p[3].name() == "#50c8ff" for p in win.camera.view.overlay.points)  # gone with the list
    # The truth scores: every accepted pixel within a pixel and a half of where the feature really is.
    bed = wb.site.bed
    item = wb.workcell.component(result.component)
    true_obj2cam = np.linalg.inv(bed.true_cam2world(wb.joints_deg)) @ item.item2world
    from calib_core.camera.projection import project_points

    for pair in wb.session.pairs:
        truth = project_points(item.features[pair.feature][None], true_obj2cam, wb.intrinsics)[0]
        assert np.linalg.norm(np.array(pair.pixel) - truth) < 1.5, pair.feature
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert len(wb.session.pairs) == 0  # one undo step
    qtbot.mouseClick(win.commands.redo, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    assert wb.session.result.estimate is not None and wb.session.result.estimate.solution.status.value == "ok", (
        win.results.status.text()
    )


def test_calibrate_on_edges_from_the_list_is_recorded_and_replay_skips_it(qtbot, window, tmp_path):
    import subprocess
    import sys

    win = window
    wb = win.workbench
    go_to_task(qtbot, win)
    wb.recording.start(tmp_path / "edges.mcap")
    qtbot.keyClick(win, Qt.Key.Key_F6)
    qtbot.waitUntil(lambda: win.finder.dialog is not None and win.finder.dialog.isVisible(), timeout=20_000)
    assert win.finder.dialog.edges_button.isEnabled()
    qtbot.mouseClick(win.finder.dialog.edges_button, Qt.MouseButton.LeftButton)
    result = wb.session.result.estimate
    assert result is not None and result.solution.method == "edges" and "OK" in win.results.verdict.text()
    assert "edge samples" in win.results.details.text()
    found = win.finder.dialog.found
    wb.recording.stop()
    from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations

    from calib_core.recording.reader import read_recording
    from calib_core.recording.schemas import FOUND_TOPIC

    (message,) = read_recording(tmp_path / "edges.mcap").topic(FOUND_TOPIC)  # Foxglove shows them on the frame found on
    annotations = ImageAnnotations.FromString(message.raw)
    assert len(annotations.circles) == len(found.result.proposals) and len(annotations.points[0].points) > 100
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "replay", str(tmp_path / "edges.mcap")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and "skipped (solved on the image's edges" in run.stdout, run.stdout + run.stderr


def test_find_points_where_the_target_cannot_be_seen_says_so_and_names_the_way(qtbot, window):
    """At the window's first screen the robot stands at home and the target is in no camera: F6 says the target is
    not in the camera's view and to go to the task, not "pick the points by hand" (no pick could)."""
    from tests.app.windows import wait_for_settled_frame

    win = window
    wait_for_settled_frame(qtbot, win)
    qtbot.keyClick(win, Qt.Key.Key_F6)
    qtbot.waitUntil(lambda: "not in the camera's view" in win.statusBar().currentMessage(), timeout=20_000)
    shown = win.statusBar().currentMessage()
    assert "Go to task" in shown and "pick the points by hand" not in shown, shown
    if win.finder.dialog is not None:  # the list, when shown, gives each feature the same reason
        assert not win.finder.dialog.found.result.found and win.finder.dialog.found.result.proposals == ()
        win.finder.dialog.close()
    # the way is on the Calibrate tab itself: Go to task there, and Find points then proposes points
    from tests.app.windows import confirm_move_if_asked

    assert win.commands.tabText(win.commands.currentIndex()) == "Calibrate"
    qtbot.mouseClick(win.commands.go_task_here, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    wb = win.workbench
    qtbot.waitUntil(
        lambda: np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), wb.task.tcp2base)[0]) < 0.01, timeout=30_000
    )
    wait_for_settled_frame(qtbot, win)
    qtbot.waitUntil(win.virtual.is_current, timeout=5_000)
    qtbot.mouseClick(win.commands.find_points, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: win.finder.dialog is not None and win.finder.dialog.isVisible(), timeout=20_000)
    assert win.finder.dialog.found.result.found, win.finder.dialog.found.result.message
