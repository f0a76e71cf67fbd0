"""The Cell tab through its widgets: a component from a mesh file placed by numbers with the views
following, one undo step per placement, a feature named by clicking (snapped to a boss's centre), a
task location by numbers, and the cell saved back to its YAML with its comments."""

import shutil

import numpy as np
import pytest
from PySide6.QtCore import QPoint, Qt

from tests.app.windows import confirm_move_if_asked
from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference
from calib_core.workcell import DEFAULT_WORKCELL, load_workcell


@pytest.fixture
def window(qtbot, tmp_path, launcher):
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(root / sub, tmp_path / sub)
    win = launcher.open(tmp_path / "workcell" / "workcell.yaml")
    qtbot.addWidget(win)
    win.resize(1500, 950)
    win.show()
    qtbot.waitUntil(lambda: win.workbench.link_up, timeout=15_000)
    yield win
    win.close()


def test_a_component_is_added_placed_by_numbers_and_undone_in_one_step(qtbot, window):
    win, wb, panel = window, window.workbench, window.cell_panel
    mesh = wb.workcell.path.parent / "meshes" / "drawer.stl"
    renders = win.virtual.renders
    panel.add_component_file(mesh, "crate")
    assert panel.component.currentText() == "crate" and wb.workcell.component("crate").kind == "component"
    assert win.commands.target.findText("crate") >= 0  # it can be a calibration target at once
    for box, value in zip(panel.xyz, (1200.0, -150.0, 400.0)):
        box.setValue(value)
    panel.rpy[2].setValue(30.0)
    T = wb.workcell.component("crate").item2world
    assert np.allclose(T[:3, 3], [1200.0, -150.0, 400.0]) and np.degrees(np.arctan2(T[1, 0], T[0, 0])) == pytest.approx(
        30.0
    )
    qtbot.waitUntil(lambda: win.virtual.renders > renders, timeout=5_000)  # the views follow
    assert wb.session.undo.undo_label == "Place crate"
    win.actions.undo()  # every placement of the crate at once
    assert np.allclose(wb.workcell.component("crate").item2world[:3, 3], [1000.0, 0.0, 0.0])
    assert panel.xyz[0].value() == pytest.approx(1000.0)
    win.actions.undo()
    assert "crate" not in [c.name for c in wb.workcell.components] and win.commands.target.findText("crate") < 0


def test_a_feature_named_by_a_click_snaps_to_the_boss_centre_and_the_cell_is_saved(qtbot, window):
    win, wb, panel = window, window.workbench, window.cell_panel
    qtbot.mouseClick(win.commands.go_task, Qt.MouseButton.LeftButton)
    confirm_move_if_asked(qtbot, win)
    qtbot.waitUntil(
        lambda: np.linalg.norm(pose_difference(wb.robot.fk(wb.joints_deg), wb.task.tcp2base)[0]) < 0.01, timeout=20_000
    )
    qtbot.waitUntil(win.virtual.is_current, timeout=5_000)
    panel.component.setCurrentText("oru_1_fixture")
    panel.pick_features.setChecked(True)
    panel.feature_name.setText("boss_centre_check")
    fixture = wb.workcell.component("oru_1_fixture")
    boss = fixture.features["boss_top_left"]
    uv = project(
        apply(invert(wb.model_cam2world()), apply(fixture.item2world, boss[None])),
        win.virtual.intrinsics,
        distort=False,
    )[0]
    x, y = win.virtual.view.image_to_widget(uv[0] + 3.0, uv[1] - 2.0)  # a click a little off the centre
    qtbot.mouseClick(win.virtual.view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x)), int(round(y))))
    assert np.allclose(fixture.features["boss_centre_check"], boss, atol=1e-4), panel.feature_info.text()
    assert "circle centre" in panel.feature_info.text()
    assert len(wb.session.pairs) == 0  # naming a feature is not a calibration pick
    panel.pick_features.setChecked(False)
    # A task location by numbers.
    panel.task_name.setText("near_drawer")
    for box, value in zip(panel.task_xyz + panel.task_rpy, (900.0, 500.0, 1300.0, 0.0, 90.0, 0.0)):
        box.setValue(value)
    panel.task_approach.setValue(120.0)
    qtbot.mouseClick(panel.add_task, Qt.MouseButton.LeftButton)
    assert "near_drawer" in [win.commands.tasks.item(i).text() for i in range(win.commands.tasks.count())]
    qtbot.mouseClick(panel.save, Qt.MouseButton.LeftButton)
    path = wb.workcell.path
    text = path.read_text()
    assert "# The paper's measured end-effector location" in text and "hand_eye_board:" in text
    reread = load_workcell(path)
    assert np.allclose(reread.component("oru_1_fixture").features["boss_centre_check"], boss, atol=1e-3)
    near = reread.task("near_drawer")
    assert np.allclose(near.tcp2base[:3, 3], [900.0, 500.0, 1300.0]) and near.approach_mm == pytest.approx(120.0)
