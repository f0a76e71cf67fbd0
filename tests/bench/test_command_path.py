"""The real-photo page's rows as the command calls the look: known answers on made-up rows, and which meshes the
command renders a model's view of."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from bench.command_path import command_section, model_view_of
from bench.photo_runs import Row


def _row(key, prior, mspd_px, status="ok", model_view=False, seconds=1.0):
    row = Row("handal_dev", prior, key, status, 1.0, mspd_px, 1.0, 1.0, 1.0, 100.0, seconds, 1920, reach=prior)
    return replace(row, model_view=model_view)


def test_each_prior_both_ways_on_the_same_views():
    prior = (30.0, 10.0)
    rows = [_row("a", prior, 6.0), _row("b", prior, 60.0, status="uncertain"), _row("c", prior, 9.0)]
    commanded = [_row("a", prior, 6.0, model_view=True, seconds=3.0)]
    commanded += [_row("b", prior, 45.0, model_view=True, seconds=5.0)]  # 15 px at 640: a wrong ok
    lines = command_section(rows, commanded)
    # view "c" was not run the command's way: left out of the bench's row beside it
    assert "| handal_dev | 30 mm / 10 deg | without the model's view (above) | 2 | 1 | 1 | 0 | 1 | 0 | 1.0 |" in lines
    assert "| handal_dev | 30 mm / 10 deg | as the command: with it | 2 | 1 | 2 | 1 | 0 | 0 | 4.0 |" in lines
    assert not any("10 mm / 3 deg" in line for line in lines)  # not run: not said


def test_no_mesh_the_command_renders_no_table():
    (line,) = command_section([_row("a", (10.0, 3.0), 2.0)], [])
    assert line.startswith("No mesh measured here")


def test_the_command_renders_a_view_of_a_box_and_none_of_a_sphere():
    import trimesh

    from calib_core.camera.intrinsics import Intrinsics

    class View:
        obj2cam = np.eye(4)
        intrinsics = Intrinsics(500.0, 500.0, 160.0, 120.0, 320, 240)

    View.obj2cam[:3, 3] = (0.0, 0.0, 500.0)
    with model_view_of(trimesh.creation.icosphere(subdivisions=3, radius=40.0), View) as view:
        assert view is None
    with model_view_of(trimesh.creation.box((80.0, 60.0, 40.0)), View) as view:
        image = view(View.obj2cam)  # the model's view at a pose, as the look asks for it
        assert image.shape[:2] == (240, 320) and image.any()
