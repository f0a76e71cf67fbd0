"""Lamps that cast shadows and glossy surfaces: a block on a plate lit from one side leaves the plate dark beyond
it (and only with shadows on); a glossy surface facing the lamp shows a highlight brighter than a matte one."""

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform as pose
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.render.studio import Lamp, Studio
from calib_core.scene import SceneItem

LENS = Intrinsics(500.0, 500.0, 160.0, 120.0, 320, 240)
OVERHEAD = pose(np.diag([1.0, -1.0, -1.0]), [0.0, 0.0, 1000.0])  # looking straight down from 1 m


def _plate_and_block() -> list[SceneItem]:
    plate = SceneItem(
        "plate", trimesh.creation.box((800.0, 800.0, 10.0)), pose(np.eye(3), [0, 0, -5.0]), color=(0.8, 0.8, 0.8)
    )
    block = SceneItem(
        "block", trimesh.creation.box((100.0, 100.0, 200.0)), pose(np.eye(3), [0, 0, 100.0]), color=(0.5, 0.5, 0.6)
    )
    return [plate, block]


def _render(studio: Studio) -> np.ndarray:
    renderer = SceneRenderer(LENS.width, LENS.height)
    try:
        renderer.set_items(_plate_and_block())
        renderer.set_studio(studio)
        return renderer.render_view(LENS, OVERHEAD, RenderOptions(show_edges=False)).astype(float).mean(axis=2)
    finally:
        renderer.close()


def test_a_lamp_from_the_left_leaves_the_plate_right_of_the_block_in_shadow_only_with_shadows_on():
    lamp = Lamp((-2000.0, 0.0, 1500.0), (0.0, 0.0, 0.0), intensity=1.0, cone_deg=40.0)
    lit = _render(Studio((lamp,), shadows=False, specular=0.0))
    shaded = _render(Studio((lamp,), shadows=True, specular=0.0))
    # image u runs with world x at 0.5 px/mm: the plate 100-180 mm right of the block's centre lies in its shadow
    # (the block is 200 mm tall, the lamp 37 deg above the horizon), the plate on the lamp's side of it does not
    v = int(LENS.cy)
    for x_mm in (100.0, 140.0, 180.0):
        u = int(LENS.cx + 0.5 * x_mm)
        assert shaded[v, u] < 0.6 * lit[v, u], x_mm
        u_lamp_side = int(LENS.cx - 0.5 * x_mm)
        assert shaded[v, u_lamp_side] > 2.0 * shaded[v, u], x_mm


def test_a_glossy_plate_shows_the_lamp_s_highlight():
    overhead_lamp = Lamp((0.0, 300.0, 1000.0), (0.0, 300.0, 0.0), intensity=1.0, cone_deg=30.0)
    matte = _render(Studio((overhead_lamp,), shadows=False, specular=0.0))
    glossy = _render(Studio((overhead_lamp,), shadows=False, specular=0.8, specular_power=20.0))
    # the lamp's mirror image in the plate, seen from the camera: half way between them, world (0, 150) mm, which
    # the camera (its y axis against the world's) sees 75 px above the image centre; far from it, no highlight
    v = int(LENS.cy - 0.5 * 150)
    assert glossy[v, int(LENS.cx)] > matte[v, int(LENS.cx)] + 20.0
    assert abs(glossy[int(LENS.cy) + 110, int(LENS.cx)] - matte[int(LENS.cy) + 110, int(LENS.cx)]) < 5.0
