"""The robot's display meshes, kept on disk after the first load.

Reading a vendor's DAE meshes through Pinocchio's loader (assimp) and converting them costs about a second
for a UR5 at every start. The converted meshes (mm, exactly what the loader gave) are stored in the user's
cache folder, one ``.npz`` per mesh file, keyed by its path, size, modification time and URDF scale. When
every mesh of a description is there, Pinocchio is handed the description with each mesh replaced by a tiny
box: it still gives every shape's link, placement and colour, and the triangles come from the cache.
"""

from __future__ import annotations

import hashlib
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import platformdirs
import trimesh

_PLACEHOLDER = "0.001 0.001 0.001"


def cache_folder() -> Path:
    return Path(platformdirs.user_cache_dir("videocal")) / "meshes"


def _key(path: str, scale) -> str | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    text = f"{os.path.abspath(path)}|{st.st_size}|{st.st_mtime_ns}|{','.join(f'{float(s):.9g}' for s in scale)}"
    return hashlib.sha1(text.encode()).hexdigest()


def _scale_of(mesh: ET.Element) -> tuple[float, ...]:
    return tuple(float(v) for v in (mesh.get("scale") or "1 1 1").split())


def load(path: str, scale) -> trimesh.Trimesh | None:
    key = _key(path, scale)
    file = cache_folder() / f"{key}.npz" if key else None
    if file is None or not file.is_file():
        return None
    try:
        with np.load(file) as data:
            return trimesh.Trimesh(data["vertices"], data["faces"], process=False)
    except (OSError, ValueError, KeyError):
        return None


def store(path: str, scale, mesh: trimesh.Trimesh) -> None:
    """Keep ``mesh`` (mm) for the mesh file ``path``; a cache that cannot be written is skipped."""
    key = _key(path, scale)
    if key is None:
        return
    folder = cache_folder()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{key}.{os.getpid()}.npz"
        np.savez(tmp, vertices=np.asarray(mesh.vertices), faces=np.asarray(mesh.faces))
        os.replace(tmp, folder / f"{key}.npz")
    except OSError:
        pass


def placeholder_description(urdf_xml: str, kind: str = "visual") -> tuple[str, dict[str, trimesh.Trimesh]] | None:
    """The description with every ``kind`` mesh replaced by a tiny box, and the cached meshes by the
    name Pinocchio gives each shape (``<link>_<index>``); ``None`` when a mesh is not cached yet."""
    root = ET.fromstring(urdf_xml)
    meshes: dict[str, trimesh.Trimesh] = {}
    for link in root.iter("link"):
        for index, element in enumerate(link.findall(kind)):
            geometry = element.find("geometry")
            mesh = None if geometry is None else geometry.find("mesh")
            if mesh is None:
                continue
            cached = load(mesh.get("filename", ""), _scale_of(mesh))
            if cached is None:
                return None
            meshes[f"{link.get('name')}_{index}"] = cached
            geometry.remove(mesh)
            ET.SubElement(geometry, "box", size=_PLACEHOLDER)
    return ET.tostring(root, encoding="unicode"), meshes
