"""A user's ROS 2 bag on the window's replay timeline: the frames of its image topic, the arm's joints at
each frame's header stamp (from ``/joint_states`` through the cell's joint names), its CameraInfo as the camera in
use; points picked on a frame and solved as on a recording. The bag is written by ``rosbags`` from the simulated
test bed (the true robot, rendered by the true camera); the truth only scores."""

import hashlib

import numpy as np
import pytest
from PySide6.QtCore import Qt

from calib_core.bags.bag_playback import BagPlayback, is_bag
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.robot import solve_ik
from calib_core.ros2.joint_units import user_per_si
from tests.core.bags.bag_writing import hold_and_move, write_arm_bag
from tests.core.operator.perfect_operator import FEATURES, pick_all
from videocal_sim.test_bed import TestBed

T0 = 1_760_000_000_000_000_000  # the robot's clock, ns


@pytest.fixture(scope="module")
def arm_bag(tmp_path_factory):
    bed = TestBed.create()
    task = next(iter(bed.workcell.task_locations.values()))
    look = solve_ik(
        bed.model_robot, task.approach2base, np.array(bed.workcell.home_joints_deg, float)
    ).q_deg  # the camera on the fixture
    turned = look + np.r_[0.5, 0.0, 0.0, 0.0, -1.5, 0.0][: len(look)]
    track, shots, moving = hold_and_move([look, turned], T0)
    camera = bed.camera()
    rendered = [(t, camera.render(q)[0]) for t, q in shots]
    bag = write_arm_bag(tmp_path_factory.mktemp("bag") / "look_bag", bed.intrinsics, bed.model_robot, rendered, track)
    return bag, bed, [q for _, q in shots], [t for t, _ in shots]


def _digest(folder) -> str:
    return hashlib.sha256(b"".join(p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file())).hexdigest()


@pytest.fixture
def window(offline_window):
    return offline_window


def test_the_bag_reads_as_a_timeline(arm_bag):
    bag, bed, joints, stamps = arm_bag
    robot = bed.model_robot
    assert is_bag(bag) and is_bag(next(bag.glob("*.mcap")))
    with BagPlayback(bag, robot.joint_names, user_per_si(robot.joint_units)) as pb:
        assert len(pb.frames) == 3 and pb.joint_topic == "/joint_states"
        assert np.allclose(pb.frames.times_s, (np.array(stamps) - stamps[0]) / 1e9)  # header stamps, not record times
        assert pb.setup["intrinsics"]["fu"] == pytest.approx(bed.intrinsics.fu)
        for k, q in enumerate(joints):  # the joints at each frame's stamp are the bag's
            assert np.allclose(pb.joints_at(pb.frames.times_s[k]), q, atol=0.05)
        image = pb.frames.image(2)
        assert image.shape == (bed.intrinsics.height, bed.intrinsics.width, 3) and image.std() > 10


def test_a_bag_replays_in_the_window_and_a_look_is_solved_on_it(qtbot, window, arm_bag):
    bag, bed, joints, stamps = arm_bag
    win, wb = window, window.workbench
    before = _digest(bag)
    win.files.open_recording(bag)
    bar = win.replay
    assert bar.isVisible() and wb.frames.replaying, win.results.status.text()
    message = win.statusBar().currentMessage()
    assert "ROS 2 bag" in message and "joints from /joint_states" in message and "3 frames" in message
    assert wb.intrinsics.fu == pytest.approx(bed.intrinsics.fu)  # the bag's CameraInfo is the camera in use

    # The last frame (the arm still at its second pose): that image, the joints of its stamp.
    bar.seek(bar.playback.duration_s)
    assert win.camera.last_frame.index == 2
    assert np.allclose(wb.joints_deg, joints[2], atol=0.05)

    # Picks on that frame carry the joints of its stamp; the solve uses them and finds the true camera pose (the
    # tool beyond it is the model's mounting: what one look can measure is the camera).
    fixture = wb.workcell.component(wb.task.component)
    corners = apply(
        invert(bed.true_cam2world(joints[2])),
        apply(fixture.item2world, np.array([fixture.features[f] for f in FEATURES if f in fixture.features])),
    )
    assert wb.intrinsics.contains(
        project(corners, wb.intrinsics)
    ).all()  # the features are on the frame, where they are picked
    pick_all(wb, bed, joints[2])
    assert all(np.allclose(p.view.joints_deg, joints[2], atol=0.05) for p in wb.session.pairs)
    qtbot.mouseClick(win.commands.calibrate, Qt.MouseButton.LeftButton)
    result = wb.session.result.estimate
    assert result is not None and result.solution.rms_px < 0.5, win.results.status.text()
    true_cam = bed.true_cam2world(joints[2])
    assert np.linalg.norm(result.cam2world_measured[:3, 3] - true_cam[:3, 3]) < 0.3
    assert np.linalg.norm(result.cam2world_model[:3, 3] - true_cam[:3, 3]) > 1.0  # the model alone was millimetres off

    qtbot.mouseClick(bar.close_button, Qt.MouseButton.LeftButton)
    assert not wb.frames.replaying and bar.playback is None
    assert _digest(bag) == before  # the bag is only read


def test_a_bag_without_images_is_named_and_changes_nothing(qtbot, window, tmp_path):
    from tests.core.bags.bag_writing import write_bag

    bag = write_bag(tmp_path / "joints_only", "sqlite3", {}, camera_info=False)
    win = window
    win.files.open_recording(bag)
    text = win.results.status.text()
    assert "joints_only" in text and "no images in this bag" in text and "/joint_states" in text
    assert not win.replay.isVisible() and not win.workbench.frames.replaying
