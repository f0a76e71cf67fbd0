"""Intrinsics from ChArUco views against the simulated camera's known truth; bad views and bad
specs are clear messages; the result round-trips through the intrinsics files."""

import subprocess
import sys

import cv2
import numpy as np
import pytest

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.vision.board import BoardSpec
from calib_core.vision.intrinsics_calibration import (
    CalibrationInputError,
    calibrate_intrinsics,
    detect_view,
    detect_views,
)
from videocal_sim.board_views import simulated_board_images

# Half the gripper camera's resolution keeps the test quick; the distortion is the real lens's.
TRUTH = Intrinsics(560.0, 558.0, 322.35, 238.15, 640, 480, (-0.18, 0.07, 0.0006, -0.0004, -0.01))
SPEC = BoardSpec()


@pytest.fixture(scope="module")
def images():
    return simulated_board_images(TRUTH, SPEC, n=12, seed=3)


def test_recovers_the_truth(images):
    views, rejected = detect_views(images, SPEC)
    assert rejected == [] and len(views) == 12
    result = calibrate_intrinsics(views, SPEC)
    i = result.intrinsics
    assert abs(i.fu / TRUTH.fu - 1) < 0.002 and abs(i.fv / TRUTH.fv - 1) < 0.002
    assert abs(i.cx - TRUTH.cx) < 1.0 and abs(i.cy - TRUTH.cy) < 1.0
    assert result.rms_px < 0.15
    assert all(result.std[k] > 0 for k in ("fu", "fv", "cx", "cy"))
    # Reported uncertainty covers the actual error.
    assert abs(i.fu - TRUTH.fu) < 4 * result.std["fu"] + 0.05
    # Without distortion modelled (the paper's tool) the fit is far worse and the focal length biased.
    pinhole = calibrate_intrinsics(views, SPEC, distortion=False)
    assert pinhole.rms_px > 5 * result.rms_px
    assert abs(pinhole.intrinsics.fu / TRUTH.fu - 1) > abs(i.fu / TRUTH.fu - 1)


def test_k3_is_held_at_zero_unless_asked_for(images):
    """Two radial terms by default (ROS's camera_calibration does the same): a third bends the model
    where the views have no corner. Asked for, it is fitted and reported with its sigma."""
    views, _ = detect_views(images, SPEC)
    two = calibrate_intrinsics(views, SPEC)
    three = calibrate_intrinsics(views, SPEC, radial_terms=3)
    assert two.intrinsics.distortion[4] == 0.0 and two.std["k3"] == 0.0
    assert three.intrinsics.distortion[4] != 0.0 and three.std["k3"] > 0.0
    assert abs(two.intrinsics.fu / TRUTH.fu - 1) < 0.002
    with pytest.raises(CalibrationInputError, match="radial_terms must be 2 .k1 k2. or 3"):
        calibrate_intrinsics(views, SPEC, radial_terms=4)


def test_bad_views_are_rejected_with_reasons(images):
    blank = np.full((480, 640, 3), 90, np.uint8)
    name, board = images[0]
    full = detect_view(name, board, SPEC)
    # Hide all of the board but a patch around a few corners.
    keep = full.corners_px[:3]
    x0, y0 = np.floor(keep.min(axis=0) - 45).astype(int)
    x1, y1 = np.ceil(keep.max(axis=0) + 45).astype(int)
    partial = np.full_like(board, 90)
    partial[max(y0, 0) : y1, max(x0, 0) : x1] = board[max(y0, 0) : y1, max(x0, 0) : x1]
    views, rejected = detect_views(
        [("blank", blank), ("partial", partial), ("ok", board), ("small", cv2.resize(board, (320, 240)))], SPEC
    )
    reasons = {r.name: r.reason for r in rejected}
    assert reasons["blank"] == "no board found"
    assert (
        "corners seen (at least 8 needed)" in reasons["partial"]
        or "markers seen but no chessboard corner" in reasons["partial"]
    )
    assert "differs from the first view" in reasons["small"]
    assert [v.name for v in views] == ["ok"]
    with pytest.raises(
        CalibrationInputError, match="1 usable board views, at least 3 needed .rejected: blank: no board found"
    ):
        calibrate_intrinsics(views, SPEC, rejected=rejected)


def test_a_wrong_board_spec_finds_nothing(images):
    other = BoardSpec.parse("charuco:9x7:30:22:DICT_4X4_50")
    result = detect_view(*images[0], other)
    assert not hasattr(result, "corners_px")
    for bad, msg in (
        ("charuco:9x7:30", "expected charuco"),
        ("charuco:2x7:30:22:DICT_5X5_100", "at least 3 x 3"),
        ("charuco:9x7:30:22:DICT_NOPE", "unknown ArUco dictionary"),
    ):
        with pytest.raises(ValueError, match=msg):
            BoardSpec.parse(bad)


def test_command_line_writes_a_loadable_file(tmp_path, images):
    folder = tmp_path / "views"
    folder.mkdir()
    for name, image in images[:8]:
        cv2.imwrite(str(folder / f"{name}.png"), image[:, :, ::-1])
    (folder / "notes.txt").write_text("not an image")
    cv2.imwrite(str(folder / "zz_blank.png"), np.full((480, 640, 3), 90, np.uint8))
    out = tmp_path / "cam_ros.yaml"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "calibrate-intrinsics",
            str(folder),
            "--out",
            str(out),
            "--format",
            "ros",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert "rejected zz_blank.png: no board found" in run.stderr
    loaded = load_intrinsics(out)
    assert abs(loaded.fu / TRUTH.fu - 1) < 0.003 and loaded.width == 640
