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
    target = SceneItem(name="target", mesh=trimesh.creation.box((60.0, 60.0, 5.0)), item2world=make_transform(np.eye(3), [0.0, 0.0, 300.0]), color=(1.0, 0.1, 0.1))
    cam2world_model = np.eye(4)  # looking along +z at the target
    finger = SceneItem(name="robot/finger", mesh=trimesh.creation.box((8.0, 30.0, 8.0)), item2world=make_transform(np.eye(3), [25.0, 20.0, 100.0]),
                       color=(0.1, 0.1, 1.0), kind="robot")
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
