"""Screenshot baselines: each pane and the whole window after a calibration, compared with PNGs in
``tests/baselines/`` within stated tolerances.

The scene is fixed (the robot at the task location, one simulated camera frame with a fixed noise
seed, six pairs, a solve), so the pictures only change when the drawing does. Comparisons are made
at half size, which forgives a one-pixel shift of an anti-aliased edge but not a missing marker,
a wrong colour or a moved pane. ``VIDEOCAL_UPDATE_BASELINES=1`` rewrites the baselines after a
deliberate change; look at them (and at ``tests/output/*_diff.png``) before committing.
"""

from calib_core.calibration.commands import ClearPairs
import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from app.gui.main_window import MainWindow
from tests.app.windows import pick_pair, window_settings
from tests.core.operator.still_robot import still_for
from app.gui.workbench import Workbench
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.robot import solve_ik
from videocal_sim.sim_site import simulated_cell
from calib_core.connectors.frame import Frame

BASELINES = Path(__file__).resolve().parents[1] / "baselines"
OUTPUT = Path(__file__).resolve().parents[1] / "output"
FEATURES = ["plate_top_left", "plate_top_right", "plate_bottom_right", "plate_bottom_left", "pin_tip", "boss_top_left"]

# Per picture: the largest mean absolute difference (grey levels, 0-255) and the largest share of pixels
# that may differ by more than 48 grey levels (text antialiasing, a shifted edge).
TOLERANCES = {
    "pane_camera": (3.0, 0.010),
    "pane_virtual": (2.0, 0.005),
    "pane_overview": (2.0, 0.005),
    "window": (3.0, 0.015),
}


@pytest.fixture
def calibrated_window(qtbot, tmp_path):
    cell, site = simulated_cell(image_scale=0.5)
    bed = site.bed  # the truth: where the operator's eyes find the features
    wb = Workbench(cell, site)
    win = MainWindow(wb, settings=window_settings(tmp_path))
    qtbot.addWidget(win)
    win.resize(1400, 900)
    win.show()
    task = wb.task
    q = solve_ik(wb.robot, task.tcp2base, wb.joints_deg).q_deg
    bed.joints_deg = q.copy()
    # No controller: joint samples of a robot standing at q, as the link would give them; the views follow.
    t = still_for(wb, joints_deg=q)
    camera = bed.camera(seed=7)
    image, _ = camera.render(q)
    camera.close()
    wb.frames.observe_frame(Frame(image, 0, t))
    fixture = wb.workcell.component("oru_1_fixture")
    true_cam = bed.true_cam2world(q)
    for name in FEATURES:
        p = apply(fixture.item2world, fixture.features[name])
        pick_pair(wb, "oru_1_fixture", name, p, project(apply(invert(true_cam), p[None]), wb.intrinsics)[0])
    win.actions.calibrate()
    qtbot.waitUntil(lambda: win.camera.edges_drawn > 0, timeout=5_000)
    win.virtual.refresh()
    win.overview.mark_dirty()
    win.overview.refresh()
    qtbot.wait(100)
    yield win
    win.close()


def _grab(widget) -> np.ndarray:
    from PySide6.QtGui import QImage

    image = widget.grab().toImage().convertToFormat(QImage.Format.Format_RGB888)
    w, h = image.width(), image.height()
    array = (
        np.frombuffer(image.constBits(), np.uint8).reshape(h, image.bytesPerLine())[:, : 3 * w].reshape(h, w, 3).copy()
    )
    return array


def _half(image: np.ndarray) -> np.ndarray:
    return cv2.resize(image, (image.shape[1] // 2, image.shape[0] // 2), interpolation=cv2.INTER_AREA)


def _compare(name: str, rgb: np.ndarray) -> None:
    shot = _half(rgb)
    path = BASELINES / f"{name}.png"
    OUTPUT.mkdir(exist_ok=True)
    cv2.imwrite(str(OUTPUT / f"{name}.png"), shot[:, :, ::-1])
    if os.environ.get("VIDEOCAL_UPDATE_BASELINES") == "1":
        BASELINES.mkdir(exist_ok=True)
        cv2.imwrite(str(path), shot[:, :, ::-1])
        return
    assert path.is_file(), f"no baseline {path}: run with VIDEOCAL_UPDATE_BASELINES=1, look at it, commit it"
    base = cv2.imread(str(path))[:, :, ::-1]
    assert base.shape == shot.shape, (
        f"{name}: {shot.shape[1]} x {shot.shape[0]} px, the baseline is {base.shape[1]} x {base.shape[0]}"
    )
    diff = np.abs(shot.astype(int) - base.astype(int)).max(axis=2)
    cv2.imwrite(str(OUTPUT / f"{name}_diff.png"), np.clip(diff * 4, 0, 255).astype(np.uint8))
    mean_limit, share_limit = TOLERANCES[name]
    mean, share = float(diff.mean()), float((diff > 48).mean())
    assert mean <= mean_limit and share <= share_limit, (
        f"{name}: mean difference {mean:.2f} (limit {mean_limit}), {100 * share:.2f} % of pixels off by > 48 (limit "
        f"{100 * share_limit:.1f} %); see tests/output/{name}_diff.png"
    )


def test_pane_and_window_baselines(calibrated_window):
    win = calibrated_window
    _compare("pane_camera", _grab(win.camera.view))
    _compare("pane_virtual", _grab(win.virtual.view))
    _compare("pane_overview", _grab(win.overview.view))
    _compare("window", _grab(win))


def test_the_comparison_catches_a_missing_overlay(calibrated_window):
    """The tolerance is not so loose that the picks and residuals could vanish unnoticed."""
    win = calibrated_window
    with_marks = _half(_grab(win.camera.view))
    win.workbench.session.undo.push(ClearPairs(win.workbench.session.pairs))
    win.camera.refresh_overlay()
    win.camera.set_edges_image(None)
    without = _half(_grab(win.camera.view))
    diff = np.abs(with_marks.astype(int) - without.astype(int)).max(axis=2)
    mean_limit, share_limit = TOLERANCES["pane_camera"]
    assert diff.mean() > mean_limit or (diff > 48).mean() > share_limit
