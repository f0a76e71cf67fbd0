"""The ASCII PLY most scanners and MeshLab write (BOP's object meshes among them), read in one pass: a vertex element
of scalar coordinates, normals and colours, and a face element of triangles. trimesh parses an ASCII PLY a line at a
time (a third of a second for LM-O's 16,000-vertex cat, longer than the look at one photo takes); NumPy's text
reader takes a twentieth of that. Any other PLY (binary, polygons, texture coordinates, more elements) is left to
trimesh, which reads them all: :func:`read_ascii_ply` then answers ``None``.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

_SCALAR_TYPES = {
    "char": np.int8,
    "int8": np.int8,
    "uchar": np.uint8,
    "uint8": np.uint8,
    "short": np.int16,
    "int16": np.int16,
    "ushort": np.uint16,
    "uint16": np.uint16,
    "int": np.int32,
    "int32": np.int32,
    "uint": np.uint32,
    "uint32": np.uint32,
    "float": np.float32,
    "float32": np.float32,
    "double": np.float64,
    "float64": np.float64,
}
_VERTEX_NAMES = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha"}
_FACE_LISTS = {"vertex_indices", "vertex_index"}
_HEADER_BYTES = 64 * 1024


def read_ascii_ply(path: str | Path):
    """The triangle mesh in the ASCII PLY at ``path`` as trimesh would read it unprocessed (vertices, faces and RGBA
    colours as the file gives them; its normals, as trimesh's loader leaves them, taken from the faces), or ``None``
    when the file is not such a PLY (trimesh reads it then, and names what is wrong with a broken one)."""
    import trimesh

    with open(path, "rb") as f:
        head = f.read(_HEADER_BYTES)  # the header decides; a binary file is never read whole here
        layout = _layout(head)
        if layout is None:
            return None
        data = head + f.read()
    body_start, vertex_count, vertex_props, face_count = layout
    lines = data[body_start:].split(b"\n", vertex_count)
    if len(lines) <= vertex_count and face_count:
        return None
    try:
        vertex_rows = np.loadtxt(io.BytesIO(b"\n".join(lines[:vertex_count])), dtype=np.float64, ndmin=2)
        face_rows = (
            np.loadtxt(io.BytesIO(lines[vertex_count]), dtype=np.int64, ndmin=2)
            if face_count
            else np.zeros((0, 4), dtype=np.int64)
        )
    except ValueError:  # ragged rows (a polygon that is no triangle), a word where a number belongs: trimesh's
        return None
    if vertex_rows.shape != (vertex_count, len(vertex_props)) or len(face_rows) != face_count:
        return None
    if face_count and (face_rows.shape[1] != 4 or np.any(face_rows[:, 0] != 3)):
        return None
    column = {name: vertex_rows[:, i].astype(kind) for i, (name, kind) in enumerate(vertex_props)}
    vertices = np.column_stack([column[a] for a in "xyz"]).astype(np.float64)
    kwargs = {}
    if {"red", "green", "blue"} <= column.keys():
        alpha = column.get("alpha", np.full(vertex_count, 255))
        kwargs["vertex_colors"] = np.column_stack([column["red"], column["green"], column["blue"], alpha]).astype(
            np.uint8
        )
    return trimesh.Trimesh(vertices=vertices, faces=face_rows[:, 1:], process=False, **kwargs)


def _layout(data: bytes) -> tuple[int, int, list[tuple[str, type]], int] | None:
    """Where the body starts, the vertex count, the vertex properties (name, type) in order and the face count;
    ``None`` for any PLY this reader leaves to trimesh."""
    end = data.find(b"end_header")  # (a header longer than the bytes read: trimesh's)
    if not data.startswith(b"ply") or end < 0 or b"\r" in data[:end]:
        return None
    newline = data.find(b"\n", end)
    if newline < 0:
        return None
    header = data[:end].decode("ascii", errors="replace").split("\n")
    if len(header) < 2 or header[1].split() != ["format", "ascii", "1.0"]:
        return None
    elements: list[list] = []  # [name, count, properties]
    for line in header[2:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "element" and len(words) == 3 and words[2].isdigit():
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property" and elements:
            elements[-1][2].append(words[1:])
        else:
            return None
    named = {e[0]: e for e in elements if e[1] > 0}
    if [e[0] for e in elements if e[1] > 0] not in (["vertex"], ["vertex", "face"]):
        return None
    _, vertex_count, vertex_words = named["vertex"]
    vertex_props = []
    for words in vertex_words:
        if len(words) != 2 or words[0] not in _SCALAR_TYPES or words[1] not in _VERTEX_NAMES:
            return None
        vertex_props.append((words[1], _SCALAR_TYPES[words[0]]))
    if not {"x", "y", "z"} <= {name for name, _ in vertex_props}:
        return None
    face_count = 0
    if "face" in named:
        _, face_count, face_words = named["face"]
        if len(face_words) != 1 or len(face_words[0]) != 4 or face_words[0][0] != "list":
            return None
        if face_words[0][3] not in _FACE_LISTS:
            return None
    return newline + 1, vertex_count, vertex_props, face_count
