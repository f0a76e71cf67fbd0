"""The Robot mode through the real window: plan, run (the robot driven over the controller link, a
view at each settled pose), identify, apply, save and revert, on a simulated robot with its typical
kinematic errors; scored against the test bed's truth."""

import numpy as np
import yaml
from PySide6.QtCore import Qt

from calib_core.frames import invert, pose_difference
from calib_core.robot import solve_ik
from calib_core.robot.model import load_robot
from videocal_sim.compliant_grasp import grasp_joints
from videocal_sim.true_robot import RobotErrors
from tests.app.windows import answer_next_question, wait_for_settled_frame

OUTPUT = __import__("pathlib").Path(__file__).resolve().parents[1] / "output"


def test_plan_run_identify_apply_save_revert(qtbot, live_window, tmp_path):
    win = live_window(RobotErrors.typical(0))
    wb, panel = win.workbench, win.robot_calibration
    win.commands.setCurrentIndex(next(i for i in range(win.commands.count()) if win.commands.tabText(i) == "Robot"))
    assert not panel.run_button.isEnabled() and not panel.identify_button.isEnabled()

    panel.show_board.setChecked(True)
    panel.poses.setValue(10)
    qtbot.mouseClick(panel.plan_button, Qt.MouseButton.LeftButton)
    assert (
        len(panel.plan.joints_deg) >= 8
        and "board poses (of" in panel.plan_text.text()
        and "views of surveyed components" in panel.plan_text.text()
    )
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
    assert len(panel.run.capture.views) == n and panel.progress.value() == n + len(panel.plan.cell_views)
    # every view keeps the joints it was taken at: the planned ones, the robot at rest
    for q, planned in zip(panel.run.capture.joints_deg, panel.plan.joints_deg):
        assert np.max(np.abs(q - planned)) < 1e-3
    OUTPUT.mkdir(exist_ok=True)
    win.grab().save(str(OUTPUT / "window_robot.png"))

    steps = []  # the identification's progress: each component's location, then the fit
    panel.progress.valueChanged.connect(lambda v: steps.append((v, panel.progress.maximum())))
    qtbot.mouseClick(panel.identify_button, Qt.MouseButton.LeftButton)
    r = panel.result
    located_steps = {v for v, top in steps if top == len(panel.run.cell_frames) + 1}
    assert located_steps >= set(range(len(panel.run.cell_frames) + 1)), steps
    assert panel.progress.value() == n + len(panel.plan.cell_views)  # the run's own progress back
    assert r.start_rms_px > 1.0 and r.rms_px < 0.3 and "parameters identified" in panel.result_text.text()
    # The camera relative to the board at a pose of the plan, against the test bed's truth.
    bed = wb.site.bed
    board2base = wb.vision.board_placement(panel._spec())
    q = panel.plan.joints_deg[-1]
    d, rot = pose_difference(invert(r.board2base) @ r.robot.fk(q, "camera"), invert(board2base) @ bed.true_cam2world(q))
    d0, rot0 = pose_difference(wb.robot.fk(q, "camera"), bed.true_cam2world(q))
    assert np.linalg.norm(d) < 0.3 * np.linalg.norm(d0) and np.linalg.norm(rot) < 0.3 * np.linalg.norm(rot0)
    # The run's views of the surveyed components tie the robot to the cell: the camera in the base frame itself.
    seen = [c for c, _ in panel.plan.cell_views if c != "via"]
    assert len(set(seen)) >= 3 and len(panel.run.cell_frames) == len(seen)
    located = [k for k in r.per_view_rms_px if k.startswith("cell_")]
    assert len(located) >= 3 and "of surveyed components" in panel.result_text.text()
    d_base, rot_base = pose_difference(r.robot.fk(q, "camera"), bed.true_cam2world(q))
    assert np.linalg.norm(d_base) < 0.1 * np.linalg.norm(d0) and np.linalg.norm(rot_base) < 0.2 * np.linalg.norm(
        rot0
    ), (d_base, d0)

    renders = win.virtual.renders
    before, intrinsics_before = wb.robot.fk(q, "camera"), wb.intrinsics
    assert panel.fit_intrinsics.isChecked() and r.intrinsics != intrinsics_before  # refined with the robot by default
    assert abs(r.intrinsics.fu - bed.intrinsics.fu) < 2.0 and abs(r.intrinsics.cx - bed.intrinsics.cx) < 2.0
    qtbot.mouseClick(panel.apply_button, Qt.MouseButton.LeftButton)
    assert np.allclose(wb.robot.fk(q, "camera"), r.robot.fk(q, "camera")) and win.virtual.renders > renders
    assert wb.intrinsics == r.intrinsics
    assert panel.revert_button.isEnabled()

    # Camera to tool: the gripper closed on each task location's pin in compliance. The simulated
    # physical world plays the compliance (the joints where the true TCP is on the pin); the window
    # only reads the joints the controller then reports.
    tool = panel.tool_group
    assert not tool.measure_button.isEnabled()
    panel.show_board.setChecked(False)  # the board taken down before the gripper works at the fixtures
    pins = {}

    def move(
        q, what, allowed=frozenset()
    ):  # awaited until the reported joints are there: the next preview starts from them
        handle = wb.moves.move_joints(q, what, confirmed=True, allowed_contacts=allowed)
        qtbot.waitUntil(lambda: handle.finished and np.max(np.abs(wb.joints_deg - q)) < 1e-3, timeout=60_000)

    home = np.asarray(wb.cell.home_joints, dtype=float)
    for task in list(wb.workcell.task_locations.values())[:2]:
        wb.set_task(task.name)
        q_approach = solve_ik(wb.robot, task.approach2base, home).q_deg
        q_pin = grasp_joints(bed, task.tcp2base, seed=len(pins), component=task.component)
        move(home, "home")
        move(q_approach, f"{task.name} approach")
        move(q_pin, f"{task.name} grasp (the compliance)", frozenset({task.component}))
        wait_for_settled_frame(qtbot, win)  # the grasp is seen on a frame of the robot at rest
        qtbot.mouseClick(tool.record_button, Qt.MouseButton.LeftButton)
        pins[task.name] = (q_pin, task.tcp2base)
        move(q_approach, f"{task.name} approach", frozenset({task.component}))  # back out of the fixture
    assert len(wb.tool.grasps) == 2 and "2 grasps" in tool.text.text(), win.statusBar().currentMessage()
    before_tool = {
        name: np.linalg.norm(pose_difference(wb.robot.fk(q_pin, "tcp"), pin)[0]) for name, (q_pin, pin) in pins.items()
    }
    qtbot.mouseClick(tool.measure_button, Qt.MouseButton.LeftButton)
    assert tool.measured_tool is not None and "TCP from 2 grasps (2 seen by the camera), spread" in tool.text.text()
    # each grasp was seen on the camera's frame (the held fixture's edges): the tool knows its own
    # uncertainty from those views, better than the survey's 0.05 mm per axis; a stored look adds it
    assert tool.measured_tool.seen_grasps == 2, win.statusBar().currentMessage()
    assert np.all(np.diag(tool.measured_tool.covariance)[:3] < 0.05**2 / 2) and np.all(
        np.diag(tool.measured_tool.covariance) > 0
    )
    # scored by the truth: the model with the seen tool puts the TCP on each pin to within the
    # calibrated camera's error there (a short calibration at 640 x 480: its principal point 0.26 px
    # off turns the camera frame by 0.5 mrad, and the seen tool with it, 0.09 mm at the TCP's lever
    # arm; the task's look below, made through the same camera, takes that out), far better than before
    for name, (q_pin, pin) in pins.items():
        miss = np.linalg.norm(pose_difference(wb.robot.fk(q_pin, "tcp"), pin)[0])
        assert miss < 0.15 and miss < 0.2 * before_tool[name], (name, miss, before_tool[name])

    win.grab().save(str(OUTPUT / "window_robot_tool.png"))

    # One look at a task location on the calibrated model: Find points' edges at the task location
    # itself (a look from elsewhere is not its correction), stored weighed against the calibrated robot
    # (its covariance there), scored by the truth.
    task = wb.workcell.task("oru_1_grasp")
    wb.set_task(task.name)
    q_look = solve_ik(wb.robot, task.tcp2base, home).q_deg
    move(home, "home")
    move(solve_ik(wb.robot, task.approach2base, home).q_deg, f"{task.name} approach")
    move(q_look, f"{task.name} task", frozenset({task.component}))
    wait_for_settled_frame(qtbot, win)
    found = wb.finder.find_points()
    edges = found.result.edges
    assert edges is not None and edges.settled, (
        (edges.converged, edges.rms_px, edges.inlier_share) if edges else "no edges"
    )
    look = wb.finder.calibrate_on_edges()
    fused = wb.robot_calibration.look_fused_with_robot(look)
    assert wb.session.result.verdict.ok and fused is not None and fused.agree, (
        wb.session.result.verdict,
        fused and fused.message,
    )
    qtbot.mouseClick(win.commands.store, Qt.MouseButton.LeftButton)
    stored = wb.session.corrections.latest(task.name)
    assert stored is not None, win.statusBar().currentMessage()
    assert "look and model agree" in stored.source, stored.source
    # the fused correction is known better than the look alone through the same tool (the tool's error,
    # shared by look and model, is in both), and no better than the tool itself
    tool_cov = tool.measured_tool.covariance_in_base(wb.robot.fk(wb.session.result.context.joints_deg, "camera"))
    look_with_tool = np.sqrt(np.diag(look.covariance + tool_cov))
    assert np.linalg.norm(stored.std_displacement_mm) < np.linalg.norm(look_with_tool[:3])
    assert np.linalg.norm(stored.std_rotation_deg) < np.linalg.norm(look_with_tool[3:])
    assert np.all(stored.std_displacement_mm >= np.sqrt(np.diag(tool_cov)[:3]) - 1e-9)

    def miss_mm(delta):
        q_task = solve_ik(wb.robot, invert(delta) @ task.tcp2base, q_look).q_deg
        return np.linalg.norm(pose_difference(bed.true_robot.fk(q_task, "tcp"), task.tcp2base)[0])

    assert miss_mm(stored.delta_base) <= max(miss_mm(look.delta_base), miss_mm(np.eye(4))) + 0.01
    assert miss_mm(stored.delta_base) <= 3 * np.linalg.norm(stored.std_displacement_mm) + 0.02
    panel.save(tmp_path)
    doc = yaml.safe_load((tmp_path / "robot_calibration.yaml").read_text())
    assert doc["tcp2cam"]["grasps"] == 2
    assert doc["observability"]["identified"] == len(r.observability.identified)
    again = load_robot(tmp_path / "videocal_arm_calibrated.urdf")
    assert np.linalg.norm(pose_difference(again.fk(q, "camera"), r.robot.fk(q, "camera"))[0]) < 1e-3

    qtbot.mouseClick(panel.revert_button, Qt.MouseButton.LeftButton)
    assert np.allclose(wb.robot.fk(q, "camera"), before)
    assert np.allclose(
        wb.robot.fk(q, "tcp"), wb.workcell.load_robot().fk(q, "tcp"), atol=1e-6
    )  # the tool taken back too
    assert wb.intrinsics == intrinsics_before
