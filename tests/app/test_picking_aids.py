"""Aids to picking by hand: where the current feature should lie (from the model, then from the pairs
already made), and a loupe that stretches contrast."""

import numpy as np

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from tests.app.windows import click_image, go_to_task

FEATURES = ["plate_bottom_left", "plate_bottom_right", "pin_tip", "boss_top_left"]


def _pick_on_model(qtbot, win, model_cam, p_world) -> None:
    """The operator clicks the feature at ``p_world`` (3,) mm in the virtual camera."""
    click_image(
        qtbot,
        win.virtual.view,
        *project(apply(invert(model_cam), p_world[None]), win.virtual.intrinsics, distort=False)[0],
    )


def _expected_mark(win):
    marks = [(u, v) for u, v, label, _ in win.camera.view.overlay.points if label == "expected"]
    return np.array(marks[0]) if marks else None


def test_the_expected_position_is_drawn_and_sharpens_after_three_pairs(qtbot, window):
    win, wb = window, window.workbench
    go_to_task(qtbot, win)
    bed = wb.site.bed  # the truth, for the operator's eyes and the score
    fixture = wb.workcell.component("oru_1_fixture")
    model_cam, true_cam = wb.model_cam2world(), bed.true_cam2world(wb.joints_deg)
    win.camera.subpixel.setChecked(False)
    misses, texts = [], []
    for name in FEATURES:
        p_world = apply(fixture.item2world, fixture.features[name])
        _pick_on_model(qtbot, win, model_cam, p_world)
        assert wb.session.pairs.pending() is not None
        mark = _expected_mark(win)
        uv_true = project(apply(invert(true_cam), p_world[None]), wb.intrinsics)[0]
        assert mark is not None, win.camera.view.overlay.text
        misses.append(float(np.linalg.norm(mark - uv_true)))
        texts.append(win.camera.view.overlay.text)
        click_image(qtbot, win.camera.view, *uv_true, zoom=4.0)
        wb.picking.accept_pair()
        assert _expected_mark(win) is None  # nothing waits: nothing expected
    # the first marks come from the model (the robot's error: many pixels off); the fourth from the pose
    # of the three pairs already made: within a couple of pixels
    assert min(misses[:3]) > 5.0 and misses[3] < 2.0, misses
    assert "from the model" in texts[0] and "from pairs 1, 2, 3" in texts[3], texts


def test_the_loupe_stretches_a_faint_patch_over_the_grey_levels(qtbot, window):
    view = window.camera.view
    image = np.full((100, 120, 3), 40, np.uint8)
    image[50:, :] = 46  # a faint edge, 6 grey levels
    view.set_image(image)
    patch = view._stretched_patch(60, 50, 10)
    assert patch.shape == (21, 21, 3) and patch.min() == 0 and patch.max() == 255
    flat = np.full((100, 120, 3), 40, np.uint8)
    view.set_image(flat)
    assert view._stretched_patch(60, 50, 10) is None  # nothing to stretch: the plain loupe


def test_a_point_is_dragged_after_accept_undone_and_a_click_on_it_selects_its_pair(qtbot, window):
    from PySide6.QtCore import QPoint, Qt

    win, wb = window, window.workbench
    go_to_task(qtbot, win)
    bed = wb.site.bed
    fixture = wb.workcell.component("oru_1_fixture")
    model_cam, true_cam = wb.model_cam2world(), bed.true_cam2world(wb.joints_deg)
    win.camera.subpixel.setChecked(False)
    for name in FEATURES[:3]:
        p_world = apply(fixture.item2world, fixture.features[name])
        _pick_on_model(qtbot, win, model_cam, p_world)
        click_image(qtbot, win.camera.view, *project(apply(invert(true_cam), p_world[None]), wb.intrinsics)[0])
        wb.picking.accept_pair()
    view = win.camera.view
    before = np.array(wb.session.pairs.get(2).pixel)
    x, y = view.image_to_widget(*before)
    target = before + (6.0, -4.0)
    tx, ty = view.image_to_widget(*target)
    qtbot.mousePress(view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x)), int(round(y))))
    qtbot.mouseMove(view, QPoint(int(round(tx)), int(round(ty))))
    qtbot.mouseRelease(view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(tx)), int(round(ty))))
    after = np.array(wb.session.pairs.get(2).pixel)
    step = 1.0 / view._scale()  # a widget pixel, in image pixels
    assert np.linalg.norm(after - target) <= 1.5 * step + 0.5 and len(wb.session.pairs) == 3  # moved, not a new pick
    assert win.table.selected_number() == 2
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert np.allclose(wb.session.pairs.get(2).pixel, before)
    # a click on pair 3's point (no drag) selects it in the table and moves nothing
    p3 = np.array(wb.session.pairs.get(3).pixel)
    x3, y3 = view.image_to_widget(*p3)
    qtbot.mouseClick(view, Qt.MouseButton.LeftButton, pos=QPoint(int(round(x3)), int(round(y3))))
    assert (
        win.table.selected_number() == 3
        and np.allclose(wb.session.pairs.get(3).pixel, p3)
        and len(wb.session.pairs) == 3
    )
    # and in the virtual camera: a click on pair 1's mark selects it and starts no new pair
    _pick_on_model(qtbot, win, model_cam, np.array(wb.session.pairs.get(1).point_world_mm))
    assert win.table.selected_number() == 1 and len(wb.session.pairs) == 3 and wb.session.pairs.pending() is None
    assert "pair 1 selected" in win.virtual.info.text()
    # while a pair waits for its image point, a click on a mark is a pick: the waiting pair's 3D point
    fourth = apply(fixture.item2world, fixture.features[FEATURES[3]])
    _pick_on_model(qtbot, win, model_cam, fourth)
    assert wb.session.pairs.pending().feature == FEATURES[3] and len(wb.session.pairs) == 4
    _pick_on_model(qtbot, win, model_cam, np.array(wb.session.pairs.get(1).point_world_mm))
    assert wb.session.pairs.pending().feature == wb.session.pairs.get(1).feature and len(wb.session.pairs) == 4


def test_a_click_off_a_round_boss_lands_on_its_centre(qtbot, window):
    win, wb = window, window.workbench
    go_to_task(qtbot, win)
    bed = wb.site.bed
    fixture = wb.workcell.component("oru_1_fixture")
    model_cam, true_cam = wb.model_cam2world(), bed.true_cam2world(wb.joints_deg)
    win.camera.subpixel.setChecked(True)
    errors = []
    for name in ("pin_tip", "boss_bottom_left"):
        p_world = apply(fixture.item2world, fixture.features[name])
        _pick_on_model(qtbot, win, model_cam, p_world)
        uv_true = project(apply(invert(true_cam), p_world[None]), wb.intrinsics)[0]
        click_image(qtbot, win.camera.view, *(uv_true + (2.5, -2.0)), zoom=4.0)  # a hand 3 px off
        errors.append(float(np.linalg.norm(np.array(wb.session.pairs.get(wb.picking.current_pair).pixel) - uv_true)))
        wb.picking.accept_pair()
    # The hand was 3.2 px off. The boss's rim puts it within 0.1-1.1 px (by the frame's noise). The knob's
    # end-face rim lies within 2 px of its silhouette, and since the simulated camera integrates its pixels
    # the two edges blend at 640 px: the rim found is 0.9-2.1 px from the truth, by frame.
    # A known limit (docs/find-points.md); the pick must still be better than the hand.
    assert errors[1] < 1.5, errors
    assert errors[0] < 2.5, errors
