"""The bundled workcell rendered from the modelled camera at the paper's task location (where the calibration looks
from); picking
round trips; the renders are saved to tests/output/ to be looked at."""

from pathlib import Path

import cv2
import numpy as np
import pytest

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.robot import solve_ik
from calib_core.robot.visuals import RobotVisuals
from calib_core.workcell import load_workcell

OUTPUT = Path(__file__).resolve().parents[2] / "output"


@pytest.fixture(scope="module")
def scene():
    cell = load_workcell()
    robot = cell.load_robot()
    q = solve_ik(robot, cell.task("oru_1_grasp").tcp2base, cell.home_joints_deg).q_deg
    intr = load_intrinsics(cell.intrinsics_path).without_distortion().scaled(0.5)
    renderer = SceneRenderer()
    renderer.set_items(cell.components + RobotVisuals.from_robot(robot).scene_items(q))
    cam2world = robot.fk(q, "camera")
    image = renderer.render_view(
        intr, cam2world, RenderOptions(highlight="oru_1_fixture", show_features=True, feature_names=True)
    )
    OUTPUT.mkdir(exist_ok=True)
    cv2.imwrite(str(OUTPUT / "render_virtual_oru_1.png"), image[:, :, ::-1])
    overview = renderer.render_overview(options=RenderOptions(highlight="oru_1"))
    cv2.imwrite(str(OUTPUT / "render_overview.png"), overview[:, :, ::-1])
    renderer.render_view(intr, cam2world, RenderOptions(highlight="oru_1"))
    yield cell, intr, cam2world, renderer, image
    renderer.close()


def test_the_target_fills_the_middle_of_the_view(scene):
    cell, intr, cam2world, _, image = scene
    oru = cell.component("oru_1_fixture")
    px = project(
        apply(invert(cam2world), apply(oru.item2world, np.array(list(oru.features.values())))), intr, distort=False
    )
    assert intr.contains(px, margin_px=10).all()
    u, v = np.round(px[list(oru.features).index("pin_tip")]).astype(int)
    assert image[v, u].tolist() != [0, 0, 0]


def test_picking_a_feature_pixel_returns_that_feature(scene):
    cell, intr, cam2world, renderer, _ = scene
    for component, name in (
        ("oru_1_fixture", "plate_top_left"),
        ("oru_1_fixture", "boss_bottom_right"),
        ("oru_1_fixture", "pin_tip"),
        ("oru_1_fixture", "plate_bottom_right"),
    ):
        item = cell.component(component)
        p_world = apply(item.item2world, item.features[name])
        u, v = project(apply(invert(cam2world), p_world[None]), intr, distort=False)[0]
        hit = renderer.pick(u + 2.0, v - 1.5, snap_radius_px=8)
        assert hit is not None and hit.component == component and hit.feature == name
        assert np.allclose(hit.point_component_mm, item.features[name])


def test_picking_a_plain_surface_point_round_trips_within_half_a_mm(scene):
    cell, intr, cam2world, renderer, _ = scene
    oru = cell.component("oru_1_fixture")
    point = np.array([0.0, -70.0, 0.0])  # on the fixture plate, away from every feature and clear of the fingers
    p_world = apply(oru.item2world, point)
    u, v = project(apply(invert(cam2world), p_world[None]), intr, distort=False)[0]
    hit = renderer.pick(u, v, snap_radius_px=0)
    assert hit.component == "oru_1_fixture" and hit.feature is None
    assert np.linalg.norm(hit.point_component_mm - point) < 0.5
    # The depth buffer agrees with the pick.
    depth = renderer.depth_mm()[int(round(v)), int(round(u))]
    z_true = apply(invert(cam2world), p_world[None])[0, 2]
    assert abs(depth - z_true) < 1.0


def test_background_and_fixtures_are_not_picked(scene):
    _, intr, _, renderer, _ = scene
    assert renderer.pick(5, 5) is None or renderer.pick(5, 5).component != "rack_1"
