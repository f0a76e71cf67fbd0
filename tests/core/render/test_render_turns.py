"""Renderers on two threads at once (the simulated camera's worker and the window's overview): they take turns at the
process's GL, so neither crashes the process (a segmentation fault inside both ``Render`` calls ended a test run)
and each still renders its own scene: every image equals the one its renderer made alone. (A synthetic pair of threads
did not crash without the turns in this machine's runs: this checks that turns keep each render its own, not the
race.)"""

import threading

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform as pose
from calib_core.render import RenderOptions, SceneRenderer
from calib_core.scene import SceneItem

LENS = Intrinsics(1200.0, 1200.0, 320.0, 240.0, 640, 480)
OVERHEAD = pose(np.diag([1.0, -1.0, -1.0]), [0.0, 0.0, 600.0])


def _scene(size_mm: float, color) -> list[SceneItem]:
    return [SceneItem("box", trimesh.creation.box((size_mm, size_mm, 50.0)), np.eye(4), color=color)]


def test_two_threads_rendering_at_once_each_get_their_own_scene():
    scenes = {"small red": _scene(60.0, (0.9, 0.1, 0.1)), "large green": _scene(200.0, (0.1, 0.9, 0.1))}
    alone = {}
    for name, items in scenes.items():
        r = SceneRenderer(LENS.width, LENS.height)
        r.set_items(items)
        alone[name] = r.render_view(LENS, OVERHEAD, RenderOptions(show_edges=False))
        r.close()
    assert not np.array_equal(alone["small red"], alone["large green"])
    mismatches, errors = [], []

    def render_many(name: str) -> None:
        try:
            for _ in range(8):  # renderers made and closed on their own thread while the other renders, as the camera's
                renderer = SceneRenderer(LENS.width, LENS.height)
                renderer.set_items(scenes[name])
                for _ in range(6):
                    image = renderer.render_view(LENS, OVERHEAD, RenderOptions(show_edges=False))
                    if not np.array_equal(image, alone[name]):
                        mismatches.append(name)
                renderer.close()
        except Exception as exc:  # reported below, in the test's thread
            errors.append(repr(exc))

    threads = [threading.Thread(target=render_many, args=(name,)) for name in scenes]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert errors == [] and mismatches == [] and not any(t.is_alive() for t in threads)
