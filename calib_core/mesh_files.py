"""A component's mesh from a file, with its limits checked: the one reader of the workcell's meshes and of
*Add component*. A binary STL says its triangle count in its header, so a 5-million-triangle file is refused before
it is read; any mesh is refused when its file or its triangle count is over the limit, when a coordinate is not
finite or absurd, or when it encloses no area (every triangle degenerate). Each error names the file and the limit.
"""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np
import trimesh

from calib_core.errors import FileFormatError
from calib_core.mesh_ply_ascii import read_ascii_ply

MESH_SUFFIXES = (".stl", ".obj", ".dae", ".glb", ".gltf", ".ply")
from calib_core.mesh_units import MESH_SCALE  # noqa: E402,F401 (the readers' units, named where --help can read them)

MAX_TRIANGLES = 2_000_000
_WINDING_FIX_TRIANGLES = 200_000  # trimesh's winding repair walks the face graph (networkx): bounded in time
"""The most triangles a component may have: a cell's CAD part decimated for viewing has tens of thousands."""
MAX_FILE_BYTES = 500 * 1024**2
MAX_COORDINATE_MM = 1e7
"""10 km: a coordinate beyond it is a unit or export error (a cell is metres across)."""


def _stl_header_triangles(path: Path) -> int | None:
    """The triangle count a binary STL declares (bytes 80-84), ``None`` for an ASCII STL (it starts 'solid' and its
    declared count does not match its size)."""
    with open(path, "rb") as f:
        head = f.read(84)
    if len(head) < 84:
        return None
    count = struct.unpack("<I", head[80:84])[0]
    if head[:5].lower() == b"solid" and path.stat().st_size != 84 + 50 * count:
        return None
    return count


def load_mesh(path: str | Path, units: str = "mm", field: str | None = None) -> trimesh.Trimesh:
    """The mesh at ``path`` in mm (``units``: the file's, ``mm``, ``cm`` or ``m``). :class:`FileFormatError` names the
    file (and
    ``field``, the workcell key that named it) for an unknown format, a file or mesh over the limits, an unreadable
    file, no triangles, non-finite or absurd coordinates, or no area."""
    path = Path(path)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise FileFormatError(
            path, f"unsupported mesh format {path.suffix!r}; use STL, OBJ, DAE, glTF/GLB or PLY", field
        )
    if units not in MESH_SCALE:
        raise FileFormatError(path, f"mesh units must be one of {', '.join(MESH_SCALE)}, got {units!r}", field)
    if not path.is_file():
        raise FileFormatError(path, "no such mesh file (or not a regular file)", field)
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise FileFormatError(
            path,
            f"a mesh file of {size / 1024**2:.0f} MB is over the limit of {MAX_FILE_BYTES / 1024**2:.0f} MB",
            field,
        )
    if path.suffix.lower() == ".stl":
        declared = _stl_header_triangles(path)
        if declared is not None and declared > MAX_TRIANGLES:
            raise FileFormatError(
                path,
                f"a mesh of {declared} triangles is over the limit of {MAX_TRIANGLES}: decimate it for viewing",
                field,
            )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter(
                "ignore"
            )  # trimesh's own warnings on a broken file: the checks below say what is wrong
            # unprocessed first: trimesh's processing drops faces with non-finite vertices without a word
            mesh = read_ascii_ply(path) if path.suffix.lower() == ".ply" else None
            if mesh is None:
                mesh = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds on a broken file; all mean the same to the user
        raise FileFormatError(path, f"cannot read the mesh: {exc}", field) from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise FileFormatError(path, "the mesh has no triangles", field)
    if len(mesh.faces) > MAX_TRIANGLES:
        raise FileFormatError(
            path,
            f"a mesh of {len(mesh.faces)} triangles is over the limit of {MAX_TRIANGLES}: decimate it for viewing",
            field,
        )
    faces = np.asarray(mesh.faces)
    if faces.min() < 0 or faces.max() >= len(mesh.vertices):
        bad = int(np.flatnonzero((faces < 0).any(axis=1) | (faces >= len(mesh.vertices)).any(axis=1))[0])
        raise FileFormatError(
            path,
            f"face {bad} names vertices {faces[bad].tolist()}, but the mesh has {len(mesh.vertices)} (numbered from "
            "0): the file is broken",
            field,
        )
    vertices = np.asarray(mesh.vertices) * MESH_SCALE[units]
    if not np.all(np.isfinite(vertices)):
        bad = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
        raise FileFormatError(
            path,
            f"the mesh has coordinates that are not finite numbers (vertex {bad}: {vertices[bad].tolist()})",
            field,
        )
    if np.abs(vertices).max() > MAX_COORDINATE_MM:
        raise FileFormatError(
            path,
            f"the mesh reaches {np.abs(vertices).max():.3g} mm from its origin, beyond {MAX_COORDINATE_MM:g} mm: "
            "are its units right (mesh_units)?",
            field,
        )
    # (after the bounds: merging vertices rounds their coordinates to integers, which a coordinate of 1e300 overflows)
    mesh.process()  # vertices shared by their faces (an STL repeats them per triangle): the edges' neighbours
    if not float(mesh.area) * MESH_SCALE[units] ** 2 > 0.0:
        raise FileFormatError(path, "the mesh has no area (every triangle is degenerate)", field)
    if len(mesh.faces) <= _WINDING_FIX_TRIANGLES and not mesh.is_winding_consistent:
        # faces wound both ways (OpenCV's tutorial box.ply): a face's normal then points in, and the creases and
        # silhouettes the edge fit and the renders take from the normals come out wrong (diagonals as creases)
        mesh.fix_normals()
    if MESH_SCALE[units] != 1.0:
        mesh.apply_scale(MESH_SCALE[units])
    return mesh
