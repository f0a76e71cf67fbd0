"""The virtual camera is the calibrated camera: markers land where ``project()`` puts them."""

from pathlib import Path

import numpy as np
import pytest
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, unproject
from calib_core.frames import apply, make_transform
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem

OUTPUT = Path(__file__).resolve().parents[2] / "output"


@pytest.fixture(scope="module")
def renderer():
    r = SceneRenderer(64, 48)
    yield r
    r.close()


def _far_dummy():
    return SceneItem(
        "dummy", trimesh.creation.box(extents=(1, 1, 1)), make_transform(np.eye(3), [0, 0, -1e4]), kind="fixture"
    )


def _marker_centroid(img, channel):
    others = [c for c in range(3) if c != channel]
    mask = (img[:, :, channel] > 150) & (img[:, :, others[0]] < 80) & (img[:, :, others[1]] < 80)
    ys, xs = np.nonzero(mask)
    weights = img[ys, xs, channel].astype(float)
    return np.array([np.average(xs, weights=weights), np.average(ys, weights=weights)])


@pytest.mark.parametrize(
    "intrinsics",
    [
        Intrinsics(410.0, 385.0, 171.3, 118.9, 333, 257),  # fu != fv, odd size, principal point off centre
        Intrinsics(1120.0, 1116.0, 645.2, 476.8, 1280, 960),  # the gripper camera
    ],
)
def test_markers_land_on_projected_pixels_all_over_the_image(renderer, intrinsics):
    renderer.set_items([_far_dummy()])
    cam2world = make_transform(np.eye(3), [10.0, -20.0, 30.0])
    rng = np.random.default_rng(0)
    targets = np.column_stack(
        [rng.uniform(0.08, 0.92, 12) * intrinsics.width, rng.uniform(0.08, 0.92, 12) * intrinsics.height]
    )
    depth = rng.uniform(300, 3000, 12)
    points_cam = unproject(targets, intrinsics, undistort=False, depth_mm=depth)
    points_world = apply(cam2world, points_cam)
    errors = []
    for p in points_world:
        img = renderer.render_view(
            intrinsics,
            cam2world,
            RenderOptions(markers=[(p, (1.0, 0.0, 0.0))], feature_size_px=5, background=(0, 0, 0)),
        )
        expected = project(apply(np.linalg.inv(cam2world), p[None]), intrinsics, distort=False)[0]
        errors.append(np.linalg.norm(_marker_centroid(img, 0) - expected))
    assert max(errors) < 0.5, errors


def test_depth_buffer_gives_camera_depth(renderer):
    intr = Intrinsics(300.0, 300.0, 160.0, 120.0, 320, 240)
    wall = SceneItem(
        "wall",
        trimesh.creation.box(extents=(4000, 4000, 10)),
        make_transform(np.eye(3), [0, 0, 1505.0]),
        kind="fixture",
    )
    renderer.set_items([wall])
    renderer.render_view(intr, np.eye(4))
    depth = renderer.depth_mm()
    assert depth.shape == (240, 320)
    assert np.allclose(depth, 1500.0, atol=0.5)


def test_render_options(renderer):
    intr = Intrinsics(300.0, 300.0, 160.0, 120.0, 320, 240)
    box = SceneItem(
        "box",
        trimesh.creation.box(extents=(200, 200, 200)),
        make_transform(np.eye(3), [0, 0, 1000.0]),
        color=(0.2, 0.2, 0.9),
    )
    renderer.set_items([box])
    plain = renderer.render_view(intr, np.eye(4), RenderOptions(background=(0, 0, 0)))
    lit = renderer.render_view(intr, np.eye(4), RenderOptions(highlight="box", background=(0, 0, 0)))
    centre = (120, 160)
    assert plain[centre][2] > plain[centre][0]  # blue box
    assert lit[centre][0] > plain[centre][0] + 40  # tinted toward orange
    rgba = renderer.render_view(intr, np.eye(4), RenderOptions(transparent_background=True))
    assert rgba.shape == (240, 320, 4) and rgba[5, 5, 3] == 0 and rgba[centre][3] == 255
    edges = renderer.render_view(intr, np.eye(4), RenderOptions(style="edges", background=(0, 0, 0)))
    assert edges[centre].sum() == 0 and edges.max() > 100  # outlines only, face interiors empty
    OUTPUT.mkdir(exist_ok=True)
    with pytest.raises(ValueError, match="style must be one of"):
        renderer.render_view(intr, np.eye(4), RenderOptions(style="toon"))


def test_depth_read_back_survives_another_window_rendering_in_between():
    intr = Intrinsics(300.0, 300.0, 160.0, 120.0, 320, 240)
    near = SceneItem(
        "near", trimesh.creation.box(extents=(4000, 4000, 10)), make_transform(np.eye(3), [0, 0, 805.0]), kind="fixture"
    )
    far = SceneItem(
        "far", trimesh.creation.box(extents=(4000, 4000, 10)), make_transform(np.eye(3), [0, 0, 3005.0]), kind="fixture"
    )
    a, b = SceneRenderer(), SceneRenderer()
    a.set_items([near])
    b.set_items([far])
    a.render_view(intr, np.eye(4))
    b.render_view(intr, np.eye(4))
    assert np.allclose(a.depth_mm(), 800.0, atol=0.5)
    assert np.allclose(b.depth_mm(), 3000.0, atol=2.0)
    a.close()
    b.close()
