"""The less kind simulated camera's parts: a form error as smooth and as large as asked, the print laid on each
face along its own axis, and the CAD left as it was (the calibration is given the CAD, the camera sees the truth)."""

import numpy as np
import trimesh

from calib_core.scene import SceneItem
from videocal_sim.real_look import (
    PRINT_TEXELS,
    TEXEL_MM,
    form_error,
    main_face_texel,
    print_tile,
    printed,
    workshop_studio,
)
from videocal_sim.test_bed import TestBed
from videocal_sim.real_look import make_less_kind


def test_the_form_error_reaches_its_amplitude_along_the_normals_smoothly_and_the_same_for_a_seed():
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=100.0)
    moved = form_error(sphere, 1.0, seed=3)
    radial = np.linalg.norm(moved.vertices, axis=1) - np.linalg.norm(
        sphere.vertices, axis=1
    )  # along the normal, on a sphere
    assert np.abs(radial).max() <= 1.0 + 1e-9 and np.abs(radial).max() > 0.999
    tangential = np.linalg.norm(np.cross(moved.vertices - sphere.vertices, sphere.vertex_normals), axis=1)
    assert tangential.max() < 1e-9
    # smooth: neighbours (about 5 mm apart) differ by a small part of the amplitude (waves of 100 mm and more)
    a, b = sphere.edges_unique.T
    assert np.abs(radial[a] - radial[b]).max() < 0.35
    np.testing.assert_array_equal(form_error(sphere, 1.0, seed=3).vertices, moved.vertices)
    assert not np.array_equal(form_error(sphere, 1.0, seed=4).vertices, moved.vertices)


def test_each_face_takes_the_print_along_its_own_axis():
    box = trimesh.creation.box((40.0, 60.0, 80.0))
    mesh, uv = printed(box)
    assert len(mesh.vertices) == 3 * len(box.faces) and uv.shape == (len(mesh.vertices), 2)
    period = TEXEL_MM * PRINT_TEXELS
    corners = mesh.vertices.reshape(-1, 3, 3)
    normals = box.face_normals
    for face, (n, pts) in enumerate(zip(normals, corners)):
        axis = int(np.abs(n).argmax())
        across = [k for k in range(3) if k != axis]
        np.testing.assert_allclose(uv[3 * face : 3 * face + 3], pts[:, across] / period)
    np.testing.assert_array_equal(
        mesh.vertices[mesh.faces].reshape(-1, 3), box.vertices[box.faces].reshape(-1, 3)
    )  # the same triangles


def test_the_workshop_bed_renders_the_truth_and_leaves_the_cad_alone():
    bed = TestBed.create()
    cad = {c.name: (c.mesh, np.array(c.mesh.vertices), c.color) for c in bed.workcell.components}
    make_less_kind(bed, form_error_mm=1.0, seed=0)
    for c in bed.workcell.components:
        mesh, vertices, color = cad[c.name]
        assert c.mesh is mesh and np.array_equal(c.mesh.vertices, vertices) and c.texture is None and c.color == color
    real = {c.name: c for c in bed.true_components}
    assert set(real) == set(cad)
    for name, item in real.items():
        assert item.texture is not None and item.texture_coords.shape == (len(item.mesh.vertices), 2)
        assert item.color == (1.0, 1.0, 1.0)  # the print carries the part's colour
        if item.kind == "component":
            gap = np.abs(item.mesh.vertices.reshape(-1, 3, 3) - cad[name][1][cad[name][0].faces]).max()
            assert 0.0 < gap <= 1.0 + 1e-9
    assert bed.camera().look.studio is not None and len(bed.camera_look.studio.lamps) == 3
    scene_names = {i.name for i in bed.true_scene(bed.joints_deg)}
    assert set(real) <= scene_names


def test_the_lamps_surround_the_components_and_each_lights_them():
    items = [SceneItem("a", trimesh.creation.box((200.0, 200.0, 200.0)), np.eye(4))]
    studio = workshop_studio(items)
    for lamp in studio.lamps:
        to_centre = np.asarray(lamp.aim_mm) - np.asarray(lamp.position_mm)
        assert np.linalg.norm(np.asarray(lamp.aim_mm)) < 1e-9  # aimed at the components' centre
        # the cone covers the components (173 mm to a corner) at the lamp's distance
        assert np.degrees(np.arctan2(173.3, np.linalg.norm(to_centre))) < lamp.cone_deg
    assert len({tuple(np.sign(lamp.position_mm[:2])) for lamp in studio.lamps}) == 3  # from three sides


def test_a_part_s_broadest_face_carries_its_own_label_and_lettering_in_ink_that_shows():
    # a fixture's front plate (200 x 150 mm, 10 mm thick) away from the origin: its broadest faces turn along z
    plate = trimesh.creation.box((200.0, 150.0, 10.0))
    plate.apply_translation((530.0, -70.0, 40.0))
    u, v, w, h = main_face_texel(plate)
    assert (w, h) == (500, 375)  # 200 and 150 mm at 0.4 mm a texel
    assert (u, v) == (int(530.0 / TEXEL_MM) % PRINT_TEXELS, int(-70.0 / TEXEL_MM) % PRINT_TEXELS)
    dark = (0.15, 0.17, 0.2)
    plain = print_tile(dark, seed=1)
    tile = print_tile(dark, seed=1, main_face=(u, v, w, h))
    rows = (np.arange(v - h // 2, v + h // 2) % PRINT_TEXELS)[:, None]
    cols = (np.arange(u - w // 2, u + w // 2) % PRINT_TEXELS)[None, :]
    face, face_plain = tile[rows, cols].astype(int), plain[rows, cols].astype(int)
    white = (face.min(axis=2) > 220).mean()
    assert 0.03 < white < 0.3  # a label, not the whole face
    assert (face_plain.min(axis=2) > 220).mean() < white
    # the lettering in a light ink on a dark part (dark ink would not show): light pixels beyond the label's
    light = (face.mean(axis=2) > 150) & (face.min(axis=2) <= 220)
    assert light.mean() > 0.002
