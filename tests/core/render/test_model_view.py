"""The modelled camera's view: what rides on the camera's joint goes with the camera."""

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from calib_core.render.model_view import ModelView
from calib_core.robot.visuals import RobotVisuals
from calib_core.scene import SceneItem
from calib_core.workcell import load_workcell


def _centroid(image: np.ndarray, channel: int) -> np.ndarray:
    """The mean pixel (2,) of where ``image`` is clearly of the colour ``channel`` (0 red, 2 blue)."""
    rgb = image.astype(int)
    others = [c for c in range(3) if c != channel]
    v, u = np.nonzero((rgb[..., channel] > rgb[..., others[0]] + 40) & (rgb[..., channel] > rgb[..., others[1]] + 40))
    assert len(u) > 50
    return np.array([u.mean(), v.mean()])


def test_an_item_riding_on_the_camera_stays_put_in_the_image_while_the_cell_moves():
    """The camera placed 10 mm to the side of where the model puts it: the target (in the cell) moves
    by f 10 / z in the image, a finger riding with the camera does not; without ``riding`` the finger
    would stay in the cell and move as the target does (what Find points' model view did before)."""
    intrinsics = Intrinsics(600.0, 600.0, 320.0, 240.0, 640, 480)
    target = SceneItem(
        name="target",
        mesh=trimesh.creation.box((60.0, 60.0, 5.0)),
        item2world=make_transform(np.eye(3), [0.0, 0.0, 300.0]),
        color=(1.0, 0.1, 0.1),
    )
    cam2world_model = np.eye(4)  # looking along +z at the target
    finger = SceneItem(
        name="robot/finger",
        mesh=trimesh.creation.box((8.0, 30.0, 8.0)),
        item2world=make_transform(np.eye(3), [25.0, 20.0, 100.0]),
        color=(0.1, 0.1, 1.0),
        kind="robot",
    )
    view = ModelView(intrinsics)
    try:
        obj2cam_model = np.linalg.inv(cam2world_model) @ target.item2world
        obj2cam_moved = make_transform(np.eye(3), [-10.0, 0.0, 0.0]) @ obj2cam_model  # the camera 10 mm to +x
        riding = view.of([target, finger], target.item2world, frozenset({"robot/finger"}), cam2world_model)
        staying = view.of([target, finger], target.item2world)
        red, blue = 0, 2
        a, b = riding(obj2cam_model), riding(obj2cam_moved)
        assert np.allclose(_centroid(b, blue), _centroid(a, blue), atol=0.5)
        assert abs((_centroid(b, red) - _centroid(a, red))[0] + 600.0 * 10.0 / 300.0) < 1.5
        c = staying(obj2cam_moved)
        assert abs((_centroid(c, blue) - _centroid(a, blue))[0] + 600.0 * 10.0 / 100.0) < 2.0
    finally:
        view.close()


def test_the_gripper_rides_on_the_camera_s_joint():
    visuals = RobotVisuals.from_robot(load_workcell().load_robot())
    riding = visuals.riding_with("camera")
    assert any(name.startswith("robot/gripper") for name in riding)
    assert not any(name.startswith("robot/link_1") for name in riding)


def test_a_box_rendered_alone_matches_the_whole_image_there_through_a_distorting_lens():
    """The box of a view (the target and a margin, what Find points renders) is the whole view's
    pixels there, with the lens's distortion: the box's pinhole camera sees exactly the ideal pixels
    the distortion map samples. Outside the box the image is black."""
    intrinsics = Intrinsics(900.0, 900.0, 330.0, 250.0, 640, 480, distortion=(-0.25, 0.1, 0.001, -0.001, 0.0))
    plate = SceneItem(
        name="plate",
        mesh=trimesh.creation.box((120.0, 80.0, 10.0)),
        item2world=make_transform(np.eye(3), [30.0, -20.0, 400.0]),
        color=(0.8, 0.5, 0.2),
    )
    boss = SceneItem(
        name="boss",
        mesh=trimesh.creation.cylinder(radius=12.0, height=20.0),
        item2world=make_transform(np.eye(3), [40.0, -10.0, 385.0]),
        color=(0.2, 0.6, 0.9),
    )
    view = ModelView(intrinsics)
    try:
        expected = view.of([plate, boss], plate.item2world)
        obj2cam = plate.item2world.copy()
        whole = expected(obj2cam)
        box = (300, 150, 520, 330)  # across the plate's right edge, far from the centre (strong distortion)
        part = expected(obj2cam, box_px=box)
        u0, v0, u1, v1 = box
        inside = whole[v0:v1, u0:u1].astype(int)
        assert inside.std() > 20  # the box holds the plate's edge and the boss, not one flat face
        assert np.abs(part[v0:v1, u0:u1].astype(int) - inside).max() <= 2
        assert part[:v0].max() == 0 and part[:, u1:].max() == 0
        # a box reaching past the image is clipped to it
        clipped = expected(obj2cam, box_px=(600, -20, 700, 40))
        assert np.abs(clipped[0:40, 600:640].astype(int) - whole[0:40, 600:640].astype(int)).max() <= 2
    finally:
        view.close()


def test_a_supersampled_box_integrates_its_pixels_and_a_coarse_one_keeps_its_edges_in_place():
    """A plate turned 5 deg: rendered plainly its edge is a staircase (every pixel one face or the other);
    2 x 2 supersampled, the pixels it crosses take shades between (as a camera's, which integrate their
    area), with its place unchanged; at half resolution the edge blurs but stays within a pixel."""
    intrinsics = Intrinsics(900.0, 900.0, 320.0, 240.0, 640, 480)
    turn = np.array([[np.cos(0.087), -np.sin(0.087), 0.0], [np.sin(0.087), np.cos(0.087), 0.0], [0.0, 0.0, 1.0]])
    plate = SceneItem(
        name="plate",
        mesh=trimesh.creation.box((200.0, 200.0, 5.0)),
        item2world=make_transform(turn, [0.0, 80.0, 500.0]),
        color=(0.9, 0.9, 0.9),
    )
    view = ModelView(intrinsics)
    try:
        expected = view.of([plate], plate.item2world)
        box = (
            200,
            150,
            440,
            280,
        )  # across the plate's top edge (v about 204 at the centre, slanting 21 px over the box)
        plain = expected(plate.item2world, box_px=box).mean(axis=2)[150:280, 200:440]
        fine = expected(plate.item2world, box_px=box, supersample=2).mean(axis=2)[150:280, 200:440]
        coarse = expected(plate.item2world, box_px=box, supersample=0.5).mean(axis=2)[150:280, 200:440]
        lo, hi = np.percentile(plain, 5), np.percentile(plain, 95)
        between = lambda image: ((image > lo + 0.15 * (hi - lo)) & (image < hi - 0.15 * (hi - lo))).sum(axis=0)  # noqa: E731  (a column's edge pixels)
        assert hi - lo > 60
        assert np.median(between(plain)) == 0 and np.median(between(fine)) >= 1
        edge_row = lambda image: np.argmax(np.abs(np.diff(image, axis=0)), axis=0)  # noqa: E731
        assert np.abs(edge_row(fine) - edge_row(plain)).max() <= 1
        assert np.median(np.abs(edge_row(coarse) - edge_row(plain))) <= 1
    finally:
        view.close()
