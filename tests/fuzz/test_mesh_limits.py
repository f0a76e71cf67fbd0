"""Meshes beyond their limits: a 5-million-triangle STL refused from its header before it is read, a mesh
with coordinates of 3e38 or no area refused, each error naming the file; through the workcell, the error names the
workcell's field too."""

from __future__ import annotations

import struct

import numpy as np
import pytest
import trimesh

from calib_core.errors import FileFormatError
from calib_core.mesh_files import MAX_TRIANGLES, load_mesh


def _binary_stl_claiming(path, triangles: int) -> None:
    """A binary STL header declaring ``triangles`` (followed by one triangle only: nothing large is written)."""
    path.write_bytes(
        b"videocal test" + b" " * 67 + struct.pack("<I", triangles) + struct.pack("<12fH", *([0.0] * 12), 0)
    )


def test_a_huge_binary_stl_is_refused_from_its_header(tmp_path):
    path = tmp_path / "huge.stl"
    _binary_stl_claiming(path, 5_000_000)
    with pytest.raises(FileFormatError, match=f"5000000 triangles is over the limit of {MAX_TRIANGLES}"):
        load_mesh(path)


def test_absurd_or_empty_meshes_are_refused_and_a_good_one_is_read_in_mm(tmp_path):
    box = trimesh.creation.box((0.1, 0.2, 0.3))  # metres
    good = tmp_path / "box.stl"
    box.export(good)
    mesh = load_mesh(good, "m")
    np.testing.assert_allclose(mesh.extents, [100.0, 200.0, 300.0], atol=1e-4)  # mm
    far = box.copy()
    far.vertices = far.vertices * 1e38
    far.export(tmp_path / "far.stl")
    flat = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], faces=[[0, 1, 2]], process=False)
    flat.export(tmp_path / "flat.stl")
    (tmp_path / "text.stl").write_text("solid nothing\nendsolid nothing\n")
    (tmp_path / "broken.ply").write_text(  # a face naming a vertex the file does not hold (IndexError from trimesh)
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n10 0 0\n0 10 0\n3 0 1 7\n"
    )
    for name, why in (
        ("broken.ply", r"face 0 names vertices \[0, 1, 7\], but the mesh has 3"),
        ("far.stl", "beyond 1e\\+07 mm: are its units right"),
        ("flat.stl", "no area|no triangles"),
        ("text.stl", "no triangles|cannot read"),
        ("missing.stl", "no such mesh file"),
    ):
        with pytest.raises(FileFormatError, match=why) as info:
            load_mesh(tmp_path / name)
        assert info.value.path.name == name
    with pytest.raises(FileFormatError, match="unsupported mesh format '.xyz'"):
        load_mesh(tmp_path / "cloud.xyz")


def test_the_workcell_names_its_field_and_the_mesh(tmp_path):
    import shutil

    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    resources = tmp_path / "resources"  # the workcell names the robot and camera beside it
    shutil.copytree(
        DEFAULT_WORKCELL.parents[1], resources, ignore=shutil.ignore_patterns("*.png", "*.mcap", "recordings")
    )
    cell = resources / DEFAULT_WORKCELL.parent.name
    text = (cell / DEFAULT_WORKCELL.name).read_text()
    first_mesh = next(line.split(":", 1)[1].strip() for line in text.splitlines() if line.strip().startswith("mesh:"))
    _binary_stl_claiming(cell / first_mesh, 5_000_000)
    with pytest.raises(FileFormatError, match=r"field 'components\[0\]\.mesh'.*5000000 triangles is over the limit"):
        load_workcell(cell / DEFAULT_WORKCELL.name)


def _chain(
    n: int, axis: str = "0 0 1", xyz: str = "0 0 0.1", rpy: str = "0 0 0", lower: str = "-1", velocity: str = "1"
) -> str:
    links = "".join(f'<link name="l{k}"/>' for k in range(n + 1))
    joints = "".join(
        f'<joint name="j{k}" type="revolute"><parent link="l{k}"/><child link="l{k + 1}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
        f'<limit lower="{lower}" upper="1" effort="1" velocity="{velocity}"/></joint>'
        for k in range(n)
    )
    return f'<robot name="chain">{links}{joints}</robot>'


@pytest.mark.parametrize(
    "text, why",
    [
        (_chain(2999), "2999 joints: over the limit of 500"),
        (_chain(3, axis="0 0 0"), "axis xyz='0 0 0' must be three finite numbers, not all zero"),
        (_chain(3, xyz="0 0 1e308"), "over 1000 m away"),
        (_chain(3, axis="nan 0 1"), "axis"),
        (_chain(3, rpy="1e23 0 0"), "rpy='1e23 0 0' turns more than 100 rad"),
        (_chain(3, lower="-1e23"), "lower='-1e23' upper='1' is beyond 100 rad"),
        (_chain(3, velocity="nan"), "limit velocity='nan' must be a finite number"),
    ],
)
def test_urdfs_beyond_a_robots_limits_are_refused_by_name(tmp_path, text, why):
    """A 2999-joint URDF ended in a MemoryError traceback; a zero axis, 1e308 m origins, a turn of 1e23 rad, a limit of
    1e23 rad and a NaN velocity loaded (and ``new-cell`` wrote a cell from them)."""
    from calib_core.robot.description import read_description

    path = tmp_path / "robot.urdf"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=why) as info:
        read_description(path)
    assert info.value.path == path
    read_description(_write(tmp_path / "ok.urdf", _chain(6)))  # a plain chain still reads


def _write(path, text):
    path.write_text(text)
    return path
