"""The ASCII PLY reader against trimesh's own on the same files (a scanner's mesh from LM-O, a coloured mesh
trimesh wrote itself), the files it leaves to trimesh, and broken ones, whose errors name the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

import calib_core.mesh_files as mesh_files
from calib_core.errors import FileFormatError
from calib_core.mesh_ply_ascii import read_ascii_ply

DATA = Path(__file__).resolve().parents[1] / "data" / "third_party"
CAT = DATA / "lmo" / "models" / "obj_000006.ply"  # VCGLIB's ASCII PLY: normals, RGBA colours, triangles
HEADER = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
SQUARE = "0 0 0\n10 0 0\n10 10 0\n0 10 0\n"


def _read_by_trimesh(path):
    """``load_mesh`` with trimesh reading every file, as before this reader."""
    fast = mesh_files.read_ascii_ply
    mesh_files.read_ascii_ply = lambda _path: None
    try:
        return mesh_files.load_mesh(path)
    finally:
        mesh_files.read_ascii_ply = fast


def _assert_same(a, b):
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.faces, b.faces)
    np.testing.assert_array_equal(a.vertex_normals, b.vertex_normals)
    np.testing.assert_array_equal(np.asarray(a.visual.vertex_colors), np.asarray(b.visual.vertex_colors))


def test_a_scanned_mesh_reads_as_trimesh_reads_it():
    assert read_ascii_ply(CAT) is not None  # this reader took it
    _assert_same(mesh_files.load_mesh(CAT), _read_by_trimesh(CAT))


def test_a_coloured_mesh_trimesh_wrote_reads_back_as_trimesh_reads_it(tmp_path):
    box = trimesh.creation.box((30.0, 20.0, 10.0))
    box.visual.vertex_colors = np.column_stack(
        [np.arange(8) * 30, 255 - np.arange(8) * 30, np.full(8, 7), np.full(8, 255)]
    ).astype(np.uint8)
    path = tmp_path / "box.ply"
    path.write_bytes(trimesh.exchange.ply.export_ply(box, encoding="ascii"))
    fast = read_ascii_ply(path)
    assert fast is not None
    np.testing.assert_array_equal(np.asarray(fast.visual.vertex_colors), np.asarray(box.visual.vertex_colors))
    _assert_same(mesh_files.load_mesh(path), _read_by_trimesh(path))


@pytest.mark.parametrize(
    "text",
    [
        HEADER + "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + SQUARE + "4 0 1 2 3\n",
        HEADER + "property float texture_u\n" + "element face 0\nend_header\n" + "0 0 0 0\n" * 4,
        HEADER.replace("ascii", "binary_little_endian") + "end_header\n",
    ],
    ids=["a quad", "texture coordinates", "binary"],
)
def test_other_plys_are_left_to_trimesh(tmp_path, text):
    path = tmp_path / "other.ply"
    path.write_text(text)
    assert read_ascii_ply(path) is None


def test_a_quad_mesh_still_loads_through_trimesh(tmp_path):
    path = tmp_path / "quad.ply"
    path.write_text(
        HEADER + "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + SQUARE + "4 0 1 2 3\n"
    )
    mesh = mesh_files.load_mesh(path)
    assert len(mesh.faces) == 2 and mesh.area == pytest.approx(100.0)


@pytest.mark.parametrize(
    "body, why",
    [
        ("0 0 0\n10 0 0\n", "cannot read the mesh|no triangles"),  # fewer vertices than declared, no faces
        (SQUARE + "3 0 1 9\n", r"face 0 names vertices \[0, 1, 9\], but the mesh has 4"),
        (SQUARE.replace("10 10 0", "10 ten 0") + "3 0 1 2\n", "cannot read the mesh"),
    ],
    ids=["short", "a face past the vertices", "a word for a number"],
)
def test_a_broken_ascii_ply_is_refused_naming_the_file(tmp_path, body, why):
    path = tmp_path / "broken.ply"
    path.write_text(HEADER + "element face 1\nproperty list uchar int vertex_indices\nend_header\n" + body)
    with pytest.raises(FileFormatError, match=why) as err:
        mesh_files.load_mesh(path)
    assert "broken.ply" in str(err.value)
