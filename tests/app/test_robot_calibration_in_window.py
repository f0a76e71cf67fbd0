"""The Robot mode through the real window: plan, run (the robot driven over the controller link, a
view at each settled pose), identify, apply, save and revert, on a simulated robot with its typical
kinematic errors; scored against the test bed's truth."""

import numpy as np
import yaml
from PySide6.QtCore import Qt

from calib_core.frames import invert, pose_difference
from calib_core.robot.model import load_robot
from calib_core.testbed.true_robot import RobotErrors
from tests.app.windows import answer_next_question

OUTPUT = __import__("pathlib").Path(__file__).resolve().parents[1] / "output"


def test_plan_run_identify_apply_save_revert(qtbot, live_window, tmp_path):
    win = live_window(RobotErrors.typical(0))
    wb, panel = win.workbench, win.robot_calibration
    win.commands.setCurrentIndex(next(i for i in range(win.commands.count()) if win.commands.tabText(i) == "Robot"))
    assert not panel.run_button.isEnabled() and not panel.identify_button.isEnabled()

    panel.show_board.setChecked(True)
    panel.poses.setValue(10)
    qtbot.mouseClick(panel.plan_button, Qt.MouseButton.LeftButton)
    assert len(panel.plan.joints_deg) >= 8 and "poses planned" in panel.plan_text.text()
    assert panel.run_button.isEnabled()

    # Cancel at the question: nothing moves.
    asked = answer_next_question(qtbot, "Cancel")
    qtbot.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    assert asked and panel.run is None and wb.motion.motion.value != "moving"

    answer_next_question(qtbot, "Run")
    qtbot.mouseClick(panel.run_button, Qt.MouseButton.LeftButton)
    assert panel.run is not None and panel.stop_button.isEnabled()
    qtbot.waitUntil(lambda: panel.run.phase in ("done", "stopped"), timeout=240_000)
    assert panel.run.phase == "done", panel.run_text.text()
    n = len(panel.plan.joints_deg)
    assert len(panel.run.capture.views) == n and panel.progress.value() == n
    # every view keeps the joints it was taken at: the planned ones, the robot at rest
    for q, planned in zip(panel.run.capture.joints_deg, panel.plan.joints_deg):
        assert np.max(np.abs(q - planned)) < 1e-3
    OUTPUT.mkdir(exist_ok=True)
    win.grab().save(str(OUTPUT / "window_robot.png"))

    qtbot.mouseClick(panel.identify_button, Qt.MouseButton.LeftButton)
    r = panel.result
    assert r.start_rms_px > 1.0 and r.rms_px < 0.3 and "parameters identified" in panel.result_text.text()
    # The camera relative to the board at a pose of the plan, against the test bed's truth.
    bed = wb.site.bed
    board2base = wb.board_placement(panel._spec())
    q = panel.plan.joints_deg[-1]
    d, rot = pose_difference(invert(r.board2base) @ r.robot.fk(q, "camera"), invert(board2base) @ bed.true_cam2world(q))
    d0, rot0 = pose_difference(wb.robot.fk(q, "camera"), bed.true_cam2world(q))
    assert np.linalg.norm(d) < 0.3 * np.linalg.norm(d0) and np.linalg.norm(rot) < 0.3 * np.linalg.norm(rot0)

    renders = win.virtual.renders
    before = wb.robot.fk(q, "camera")
    qtbot.mouseClick(panel.apply_button, Qt.MouseButton.LeftButton)
    assert np.allclose(wb.robot.fk(q, "camera"), r.robot.fk(q, "camera")) and win.virtual.renders > renders
    assert panel.revert_button.isEnabled()

    panel.save(tmp_path)
    doc = yaml.safe_load((tmp_path / "robot_calibration.yaml").read_text())
    assert doc["observability"]["identified"] == len(r.observability.identified)
    again = load_robot(tmp_path / "videocal_arm_calibrated.urdf")
    assert np.linalg.norm(pose_difference(again.fk(q, "camera"), r.robot.fk(q, "camera"))[0]) < 1e-3

    qtbot.mouseClick(panel.revert_button, Qt.MouseButton.LeftButton)
    assert np.allclose(wb.robot.fk(q, "camera"), before)
