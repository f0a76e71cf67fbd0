"""The simulated test bed: the true robot differs from the model as real robots do, and the
simulated camera sees the true pose through the real lens."""

from pathlib import Path

import cv2
import numpy as np
import pytest
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project
from calib_core.frames import invert, make_transform, pose_difference
from calib_core.robot import solve_ik
from calib_core.scene import SceneItem
from videocal_sim.sim_camera import CameraLook, SimulatedCamera, samples_per_pixel
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

OUTPUT = Path(__file__).resolve().parents[2] / "output"
SMALL_LENS = Intrinsics(280.0, 279.0, 161.3, 119.2, 320, 240, (-0.18, 0.07, 0.0006, -0.0004, -0.01))


@pytest.fixture(scope="module")
def bed():
    return TestBed.create()


def test_commanding_model_joints_leaves_the_true_tool_a_few_mm_off(bed):
    q = solve_ik(bed.model_robot, bed.workcell.task("oru_1_grasp").tcp2base, bed.workcell.home_joints_deg).q_deg
    d, rv = pose_difference(bed.true_robot.fk(q), bed.model_robot.fk(q))
    assert 1.0 < np.linalg.norm(d) < 15.0
    assert 0.05 < np.linalg.norm(rv) < 1.5
    exact = TestBed.create(errors=RobotErrors.none())
    assert np.allclose(exact.true_robot.fk(q), exact.model_robot.fk(q), atol=1e-9)
    assert np.allclose(exact.true_cam2world(q), exact.model_cam2world(q), atol=1e-9)


def test_hand_eye_error_moves_only_the_camera(bed):
    errors = RobotErrors(hand_eye_xyz_mm=np.array([1.0, -2.0, 0.5]))
    other = TestBed.create(errors=errors)
    q = np.array([-20.0, 10.0, 5.0, 0.0, -15.0, 0.0])
    assert np.allclose(other.true_robot.fk(q, "tcp"), other.model_robot.fk(q, "tcp"), atol=1e-9)
    cam_true_in_model_cam = invert(other.model_cam2world(q)) @ other.true_cam2world(q)
    assert np.allclose(cam_true_in_model_cam[:3, 3], [1.0, -2.0, 0.5], atol=1e-9)


def _bright_dot_camera(points_world, look):
    dots = [
        SceneItem(
            f"dot{i}",
            trimesh.creation.icosphere(radius=1.2, subdivisions=2),
            make_transform(np.eye(3), p),
            color=(1, 1, 1),
        )
        for i, p in enumerate(points_world)
    ]
    cam2world = np.eye(4)
    return SimulatedCamera(SMALL_LENS, lambda q: dots, lambda q: cam2world, lambda: np.zeros(6), look=look)


def test_features_land_where_the_distorted_projection_puts_them():
    rng = np.random.default_rng(3)
    targets = np.column_stack([rng.uniform(25, 295, 8), rng.uniform(20, 220, 8)])
    from calib_core.camera.projection import unproject

    points = unproject(targets, SMALL_LENS, undistort=True, depth_mm=400.0)
    look = CameraLook(noise_sigma=0.0, vignetting=0.0, gain=1.0, background=(0, 0, 0))
    for p, target in zip(points, targets):
        cam = _bright_dot_camera([p], look)
        image = cam.read().image
        grey = image.astype(float).sum(axis=2)
        ys, xs = np.nonzero(grey > 60)
        centroid = np.array([np.average(xs, weights=grey[ys, xs]), np.average(ys, weights=grey[ys, xs])])
        assert np.linalg.norm(centroid - project(p[None], SMALL_LENS)[0]) < 0.5
        cam.close()


def test_frames_are_deterministic_for_a_seed_and_report_truth(bed):
    bed.joints_deg = solve_ik(
        bed.model_robot, bed.workcell.task("oru_1_grasp").approach2base, bed.workcell.home_joints_deg
    ).q_deg
    small = bed.intrinsics.scaled(0.25)
    a = bed.camera(seed=7, intrinsics=small)
    b = bed.camera(seed=7, intrinsics=small)
    c = bed.camera(seed=8, intrinsics=small)
    fa, fb, fc = a.read(), b.read(), c.read()
    assert fa.image.shape == (240, 320, 3) and fa.index == 0 and a.read().index == 1
    assert np.array_equal(fa.image, fb.image)
    assert not np.array_equal(fa.image, fc.image)
    assert np.allclose(a.last_truth.cam2world, bed.true_cam2world(bed.joints_deg))
    # The truth is not the model: the camera really is somewhere else.
    d, _ = pose_difference(a.last_truth.cam2world, bed.model_cam2world(bed.joints_deg))
    assert np.linalg.norm(d) > 0.5
    OUTPUT.mkdir(exist_ok=True)
    cv2.imwrite(str(OUTPUT / "sim_camera_oru_1_approach.png"), fa.image[:, :, ::-1])
    for cam in (a, b, c):
        cam.close()


def _edge_column_px(supersample: int, edge_u: float) -> float:
    """Where a bright card's left edge lies in the image of a pinhole camera (column, px), from the
    row's light: each pixel's share of the card is its brightness over the card's."""
    lens = Intrinsics(280.0, 280.0, 160.0, 120.0, 320, 240)
    depth = 400.0
    x_left = (edge_u - lens.cx) * depth / lens.fu
    card = trimesh.creation.box(extents=[200.0, 100.0, 1.0])
    item = SceneItem("card", card, make_transform(np.eye(3), [x_left + 100.0, 0.0, depth]), color=(1, 1, 1))
    look = CameraLook(noise_sigma=0.0, vignetting=0.0, gain=1.0, background=(0, 0, 0), supersample=supersample)
    cam = SimulatedCamera(lens, lambda q: [item], lambda q: np.eye(4), lambda: np.zeros(6), look=look)
    row = cam.read().image[120, :, 1].astype(float)
    cam.close()
    bright = float(np.mean(row[112:130]))
    covered = row[90:112] / bright  # pixels 90..111: the card covers those past the edge, whole from 112
    return 112 - 0.5 - float(covered.sum())


def test_pixels_integrate_the_light_over_their_area():
    """A sensor's pixel sums the light over its area, so an edge's sub-pixel place shows in the
    pixel it crosses; a renderer's point sample per pixel moves the edge in whole pixels (the steps
    that tilted edge fits by up to 1.2 mrad)."""
    offsets = [0.1, 0.3, 0.45, 0.6, 0.85]
    assert (
        samples_per_pixel(CameraLook(), 640) == 4
        and samples_per_pixel(CameraLook(), 1280) == 2
        and samples_per_pixel(CameraLook(supersample=1), 640) == 1
    )
    point_sampled = [abs(_edge_column_px(1, 100.0 + f) - (100.0 + f)) for f in offsets]
    integrated = [abs(_edge_column_px(4, 100.0 + f) - (100.0 + f)) for f in offsets]
    assert max(point_sampled) > 0.25  # whole-pixel steps
    assert max(integrated) <= 0.125 + 0.03  # quarter-pixel steps: the box filter of 4 x 4 samples


def test_live_video_point_samples_a_moving_scene_and_integrates_it_at_rest():
    """The window's camera: the first frame of a scene that changed is point-sampled when the robot
    moves during its render (cheap: nothing is measured on it), the next frame of the same scene
    integrates its pixels; a robot already at rest gets an integrated first frame (a slow machine
    may deliver that frame after the robot has been still long enough to be measured on)."""
    lens = Intrinsics(280.0, 280.0, 160.0, 120.0, 320, 240)
    x_left = (100.3 - lens.cx) * 400.0 / lens.fu  # the card's edge 0.2 px into pixel 100's right half
    card = SceneItem(
        "card",
        trimesh.creation.box(extents=[200.0, 100.0, 1.0]),
        make_transform(np.eye(3), [x_left + 100.0, 0.0, 400.0]),
        color=(1, 1, 1),
    )
    look = CameraLook(noise_sigma=0.0, vignetting=0.0, gain=1.0, background=(0, 0, 0))
    ticks = iter(range(10**6))
    moving = SimulatedCamera(
        lens,
        lambda q: [card],
        lambda q: np.eye(4),
        lambda: np.full(6, float(next(ticks))),
        look=look,
        coarse_while_moving=True,
    )
    first, second, third = (moving.read().image[120, :, 1].astype(float) for _ in range(3))
    moving.close()
    bright = float(np.mean(second[112:130]))
    assert first[100] == 0.0 and first[101] > 0.9 * bright  # the pixel's centre is off the card: all or nothing
    assert 0.1 * bright < second[100] < 0.3 * bright  # a fifth of the pixel is card
    assert np.array_equal(second, third)  # the same scene: the integrated render stays

    resting = SimulatedCamera(
        lens, lambda q: [card], lambda q: np.eye(4), lambda: np.zeros(6), look=look, coarse_while_moving=True
    )
    at_rest = resting.read().image[120, :, 1].astype(float)
    resting.close()
    assert np.array_equal(at_rest, second)

    # a controller's last samples on the way in differ by a thousandth of a degree: at rest too (a point-sampled frame
    # there counts as settled and aliases what is measured on it)
    creep = iter(range(10**6))
    creeping = SimulatedCamera(
        lens,
        lambda q: [card],
        lambda q: np.eye(4),
        lambda: np.full(6, 0.001 * next(creep)),
        look=look,
        coarse_while_moving=True,
    )
    arriving = creeping.read().image[120, :, 1].astype(float)
    creeping.close()
    assert np.array_equal(arriving, second)
