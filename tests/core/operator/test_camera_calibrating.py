"""The core's camera calibration (``core.vision``) without a window: the board, where it stands and the poses that see
it, and the gates on using a result (the image size, checks that failed only when confirmed)."""

from types import SimpleNamespace

import numpy as np
import pytest

from calib_core.calibration.errors import CalibrationError
from calib_core.errors import OperatorError
from calib_core.frames import concat, invert, transform_from_xyz_rpy
from calib_core.operator.camera_calibrating import MountingResult
from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore


@pytest.fixture
def core():
    return OperatorCore(Cell.open())


def test_a_board_goes_up_in_the_cell_and_a_new_one_sets_the_old_views_aside(core):
    said = []
    core.log.message.connect(said.append)
    vision = core.vision
    with pytest.raises(ValueError):
        vision.set_board("charuco:nonsense")
    board2base = vision.show_board(None, True)
    assert len(core.cell.extras) == 1 and np.allclose(board2base, vision.board_placement())
    vision.set_board("charuco:7x5:30:22:DICT_5X5_100")
    assert str(vision.capture.spec) == "charuco:7x5:30:22:DICT_5X5_100"
    assert len(core.cell.extras) == 1  # the shown board replaced by the new one
    vision.show_board(None, False)
    assert core.cell.extras == [] and not vision.board_shown


def test_the_board_poses_are_planned_once_and_stepped_through(core):
    q1, what1 = core.vision.next_board_pose()
    q2, what2 = core.vision.next_board_pose()
    n = len(core.vision.plan)
    assert n >= 2 and what1 == f"board pose 1 of {n}" and what2 == f"board pose 2 of {n}"
    assert not np.allclose(q1, q2)
    # each planned pose's modelled camera looks at the board (its centre in front of the camera)
    board2base = core.vision.board_placement()
    for q in core.vision.plan[:3]:
        board_in_cam = concat(board2base, invert(core.robot.fk(q, "camera")))
        assert board_in_cam[2, 3] > 100.0


def test_intrinsics_of_another_image_size_are_refused_by_name(core):
    other = core.intrinsics.scaled(0.5)
    with pytest.raises(CalibrationError, match=f"{other.width} x {other.height} px images"):
        core.vision.apply_intrinsics(other)


def test_a_mounting_that_failed_its_checks_is_used_only_with_those_checks_confirmed(core):
    events = []
    core.log.event.connect(lambda kind, detail: events.append(kind))
    before = core.robot.frame_placement("camera")
    flange = core.robot.frame_placement("flange")
    moved = concat(concat(before, invert(flange)), transform_from_xyz_rpy([2.0, 0.0, 0.0], [0.0, 0.0, 0.0]))
    core.vision.mounting = MountingResult(SimpleNamespace(cam2flange=moved, rms_px=0.9), 2.0, 0.0, ["poses disagree"])
    with pytest.raises(OperatorError, match="failed its checks \\(poses disagree\\): confirm it"):
        core.vision.apply_calibrated_mounting()
    with pytest.raises(OperatorError, match="confirm it"):
        core.vision.apply_calibrated_mounting(["another problem"])
    assert np.allclose(core.robot.frame_placement("camera"), before)  # nothing applied
    core.vision.apply_calibrated_mounting(["poses disagree"])
    assert np.allclose(concat(core.robot.frame_placement("camera"), invert(flange)), moved)
    assert "vision_result_confirmed" in events


def test_a_recorded_set_replaces_the_views_only_when_read_whole(core, tmp_path):
    """A set is read view by view with progress; cancelled, or with an image missing, the views captured before stay
    as they were; read whole, its views carry the recorded flange poses and are named by their files."""
    import json

    from calib_core.errors import FileFormatError
    from tests.app.recorded_sets import recorded_set

    vision = core.vision
    before = vision.capture
    path = recorded_set(tmp_path / "set", moved_view=3, moved_mm=15.0)
    seen = []
    with pytest.raises(OperatorError, match="reading poses.json was cancelled: the views are as they were"):
        vision.read_set(path, lambda done, total: seen.append((done, total)) or done < 2)
    assert vision.capture is before and seen == [(0, 10), (1, 10), (2, 10)]
    broken = json.loads(path.read_text())
    broken["poses"][5]["image"] = "images/gone.png"
    (tmp_path / "set" / "broken.json").write_text(json.dumps(broken))
    with pytest.raises(FileFormatError, match="gone.png"):
        vision.read_set(tmp_path / "set" / "broken.json")
    assert vision.capture is before
    assert vision.read_set(path) == (10, 0)
    capture, poses = vision.capture, json.loads(path.read_text())["poses"]
    assert [v.name for v in capture.views] == [p["image"].split("/")[-1][: -len(".png")] for p in poses]
    assert all(q is None for q in capture.joints_deg)
    assert all(np.allclose(F, p["flange2base"]) for F, p in zip(capture.flange2base, poses))  # mm, as recorded
