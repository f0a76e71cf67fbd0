"""A printed box on a wood-grained table, rendered by videocal's renderer with its truth known (for tests and the
real-photo bench): the difficulties
of OpenCV's photographed cookie box (a frame printed 12 mm inside every face's edge, lettering, a table with
grain and a shadow-dark patch) where the truth can score. A render, not a photograph."""

from __future__ import annotations

import cv2
import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics

CAMERA = Intrinsics(1450.0, 1450.0, 359.0, 240.0, 718, 480)
SIZE_MM = (190.0, 258.0, 75.0)


def printed_face_texture(seed: int = 0, size: int = 256) -> np.ndarray:
    """A yellow face with a dark red frame inside its edges, blue and white pictures and lettering."""
    rng = np.random.default_rng(seed)
    tex = np.zeros((size, size, 3), np.uint8)
    tex[:] = (225, 180, 40)
    inset = size // 14
    cv2.rectangle(tex, (inset, inset), (size - inset, size - inset), (120, 20, 20), 4)
    cv2.rectangle(tex, (inset + 14, inset + 14), (size - inset - 14, size - inset - 14), (90, 130, 200), -1)
    for _ in range(40):
        x, y = rng.integers(inset + 16, size - inset - 16, 2)
        cv2.circle(tex, (int(x), int(y)), int(rng.integers(3, 12)), tuple(int(c) for c in rng.integers(0, 255, 3)), -1)
    cv2.putText(tex, "GALLETAS", (inset + 6, size - inset - 20), cv2.FONT_HERSHEY_SIMPLEX, 0.7, (110, 10, 10), 2)
    return tex


def printed_box() -> tuple[trimesh.Trimesh, np.ndarray, np.ndarray]:
    """The box (mm, its centre at the origin) as 6 faces with their own vertices, the texture atlas (one face
    texture) and per-vertex texture coordinates."""
    x, y, z = SIZE_MM
    corners = np.array([[i * x, j * y, k * z] for i in (-0.5, 0.5) for j in (-0.5, 0.5) for k in (-0.5, 0.5)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    vertices, faces, uv = [], [], []
    for q in quads:
        base = len(vertices)
        vertices += [corners[i] for i in q]
        uv += [(0, 0), (1, 0), (1, 1), (0, 1)]
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    mesh = trimesh.Trimesh(np.array(vertices), np.array(faces), process=False)
    mesh.fix_normals()
    return mesh, printed_face_texture(), np.array(uv, float)


def wood_table(seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    h, w = CAMERA.height, CAMERA.width
    v = np.arange(h)[:, None] + 6.0 * np.sin(np.arange(w)[None, :] / 40.0)
    grain = 0.5 + 0.5 * np.sin(v / 3.0 + rng.normal(0, 0.3, (h, w)))
    table = np.stack([150 + 40 * grain, 90 + 25 * grain, 40 + 10 * grain], axis=2)
    table[300:420, 430:700] *= 0.45  # a dark patch beside the box (its shadow, a reflection)
    return np.clip(table, 0, 255).astype(np.uint8)


TRUTH = np.eye(4)
TRUTH[:3, :3] = Rotation.from_euler("zyx", [35.0, 0.0, -130.0], degrees=True).as_matrix()
TRUTH[:3, 3] = [-20.0, 10.0, 1100.0]


def render(noise_seed: int = 0, printed: bool = True) -> np.ndarray:
    """The photo (h, w, 3) uint8 RGB of the printed box (or, ``printed`` False, a plain yellow one) at :data:`TRUTH` on
    the table, with sensor noise."""
    from calib_core.render.renderer import RenderOptions, SceneRenderer
    from calib_core.scene import SceneItem

    mesh, texture, uv = printed_box()
    renderer = SceneRenderer(CAMERA.width, CAMERA.height)
    try:
        item = (
            SceneItem("box", mesh, TRUTH, color=(1.0, 1.0, 1.0), texture=texture, texture_coords=uv)
            if printed
            else SceneItem("box", mesh, TRUTH, color=(0.9, 0.75, 0.2))
        )
        renderer.set_items([item])
        rgba = renderer.render_view(CAMERA, np.eye(4), RenderOptions(transparent_background=True, show_edges=False))
    finally:
        renderer.close()
    alpha = rgba[:, :, 3:4] / 255.0
    image = rgba[:, :, :3] * alpha + wood_table() * (1 - alpha)
    image = cv2.GaussianBlur(image.astype(np.float32), (0, 0), 0.7) + np.random.default_rng(noise_seed).normal(
        0, 2.5, image.shape
    )
    return np.clip(image, 0, 255).astype(np.uint8)


def silhouette_centre_px() -> tuple[float, float]:
    """The box's centre in the image at :data:`TRUTH` (px)."""
    from calib_core.camera.projection import project_points

    mesh, _, _ = printed_box()
    u, v = project_points(np.asarray(mesh.vertices).mean(axis=0)[None], TRUTH, CAMERA)[0]
    return float(u), float(v)
