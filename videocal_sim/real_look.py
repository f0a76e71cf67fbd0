"""A less kind simulated camera: what a real camera on a real cell shows and the CAD does not.

The parts carry print (labels, text, a bar code: inner edges that are not the part's outline), the cell is lit
by three lamps from different sides that cast shadows and leave highlights on glossy surfaces, the sensor is
noisier and the lens a little soft, and every part differs from its CAD model by up to a millimetre (a smooth
form error, as casting and machining leave). The test bed's truth is what is rendered; the CAD is what the
calibration is given.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import trimesh

from calib_core.render.studio import Lamp, Studio
from calib_core.scene import SceneItem
from videocal_sim.sim_camera import CameraLook
from videocal_sim.test_bed import TestBed

TEXEL_MM = 0.4
"""The print's resolution on the part (mm a texel): finer than a pixel at the camera's working distance."""
WORKSHOP_FORM_ERROR_MM = 1.0
"""The largest distance of a workshop part's surface from its CAD (mm)."""
WORKSHOP_FORM_TOLERANCE_MM = 0.5
"""What the workshop cell's drawings state of its parts: features within 1 mm of their CAD positions, 1-sigma 0.5 mm a
axis (the form error's field has an RMS of 0.4-0.55 of its peak)."""
PRINT_TEXELS = 1024
"""The print's tile (texels a side); it repeats every ``PRINT_TEXELS * TEXEL_MM`` mm."""


def workshop_studio(components: list[SceneItem]) -> Studio:
    """Three lamps around the cell's components (world frame, z up): a key light high at the front left, a weaker
    fill from the right and a rim light from behind, each casting shadows; and the camera's own weak ring light."""
    corners = (
        np.vstack([trimesh.transform_points(c.mesh.bounds, c.item2world) for c in components])
        if components
        else np.zeros((2, 3))
    )
    centre = corners.mean(axis=0)
    radius = float(max(np.linalg.norm(corners - centre, axis=1).max(), 300.0))
    distance = 2.5 * radius + 1500.0
    cone = float(np.degrees(np.arctan2(1.3 * radius, distance)) + 8.0)

    def lamp(direction, intensity):
        d = np.asarray(direction, float) / np.linalg.norm(direction)
        return Lamp(tuple(centre + distance * d), tuple(centre), intensity, cone)

    return Studio(
        (lamp((-0.6, -0.5, 0.9), 0.8), lamp((0.8, -0.2, 0.5), 0.45), lamp((0.1, 0.9, 0.7), 0.35)),
        ring_light=0.3,
        ambient=0.25,
    )


def real_camera_look(components: list[SceneItem]) -> CameraLook:
    """The camera's look in a workshop: the lamps of :func:`workshop_studio`, sensor noise of 5 grey levels, a lens
    blur of 0.8 px, stronger vignetting."""
    return CameraLook(noise_sigma=5.0, blur_sigma_px=0.8, vignetting=0.35, gain=1.0, studio=workshop_studio(components))


def form_error(mesh: trimesh.Trimesh, amplitude_mm: float, seed: int) -> trimesh.Trimesh:
    """``mesh`` with every vertex moved along its normal by a smooth field of at most ``amplitude_mm`` (mm): waves
    100-400 mm long in random directions, the same for a seed."""
    rng = np.random.default_rng(seed)
    v = np.asarray(mesh.vertices, float)
    field = np.zeros(len(v))
    for _ in range(4):
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        wavelength = rng.uniform(100.0, 400.0)
        field += np.sin(2 * np.pi * (v @ direction) / wavelength + rng.uniform(0, 2 * np.pi))
    peak = np.abs(field).max()
    if peak > 0:
        field *= amplitude_mm / peak
    moved = mesh.copy()
    moved.vertices = v + field[:, None] * np.asarray(mesh.vertex_normals, float)
    return moved


def main_face_texel(mesh: trimesh.Trimesh) -> tuple[int, int, int, int]:
    """Where the print of ``mesh``'s broadest face lies on the tile (:func:`printed` lays it): ``(u, v)`` texels of
    the centre of the faces turned along the axis that holds most of the mesh's area, and their extent ``(w, h)``
    in texels (a fixture's front plate: the face a camera is brought to)."""
    axis = np.abs(mesh.face_normals).argmax(axis=1)
    area = np.bincount(axis, weights=mesh.area_faces, minlength=3)
    main = int(area.argmax())
    across = [k for k in range(3) if k != main]
    corners = mesh.vertices[mesh.faces[axis == main]].reshape(-1, 3)[:, across]
    low, high = corners.min(axis=0), corners.max(axis=0)
    u, v = ((low + high) / 2.0 / TEXEL_MM) % PRINT_TEXELS
    w, h = (high - low) / TEXEL_MM
    return int(u), int(v), int(w), int(h)


def print_tile(
    color: tuple[float, float, float], seed: int, main_face: tuple[int, int, int, int] | None = None
) -> np.ndarray:
    """A tile of print (``PRINT_TEXELS`` square, RGB uint8) on a part of ``color``: labels with text and a bar
    code, painted lines and a logo, in ink that shows on the part (dark on a light part, light on a dark one) and
    white, placed by ``seed``; ``main_face`` (:func:`main_face_texel`): a label and a stencilled name on the part's
    broadest face too, where a camera brought to the part sees it."""
    rng = np.random.default_rng(seed)
    n = PRINT_TEXELS
    base = np.clip(np.asarray(color, float) * 255.0, 0, 255)
    tile = np.empty((n, n, 3), np.uint8)
    tile[:] = base.astype(np.uint8)
    dark_part = float(base.mean()) < 90.0
    ink = (205, 205, 196) if dark_part else tuple(int(c * 0.25) for c in base)
    if main_face is not None:
        _face_print(tile, main_face, ink, rng)
    # a label: a white card with text and a bar code (about 100 x 50 mm)
    x, y = int(rng.uniform(0, n - 260)), int(rng.uniform(0, n - 130))
    cv2.rectangle(tile, (x, y), (x + 250, y + 125), (235, 235, 228), -1)
    cv2.putText(
        tile,
        f"PART {int(rng.integers(1000, 9999))}",
        (x + 14, y + 42),
        cv2.FONT_HERSHEY_SIMPLEX,
        1.1,
        (20, 20, 20),
        3,
        cv2.LINE_AA,
    )
    for k in range(36):
        if rng.random() < 0.55:
            bx = x + 14 + 6 * k
            cv2.rectangle(tile, (bx, y + 62), (bx + int(rng.integers(2, 5)), y + 112), (15, 15, 15), -1)
    for _ in range(2):  # painted lines straight on the part
        x0, y0 = rng.integers(0, n, 2)
        x1, y1 = rng.integers(0, n, 2)
        cv2.line(tile, (int(x0), int(y0)), (int(x1), int(y1)), ink, int(rng.integers(3, 8)), cv2.LINE_AA)
    cx, cy = rng.integers(80, n - 80, 2)
    cv2.circle(tile, (int(cx), int(cy)), 60, ink, 7, cv2.LINE_AA)
    cv2.putText(
        tile,
        "KEEP CLEAR",
        (int(rng.uniform(0, n - 330)), int(rng.uniform(50, n))),
        cv2.FONT_HERSHEY_DUPLEX,
        1.4,
        ink,
        3,
        cv2.LINE_AA,
    )
    return tile


def _face_print(tile: np.ndarray, face: tuple[int, int, int, int], ink: tuple, rng: np.random.Generator) -> None:
    """A part's own print on its broadest face (``face``: centre and extent in texels, :func:`main_face_texel`): a
    small white label with a part number and a bar code at the middle of one side, and a stencilled instruction
    left of the face's middle, each drawn at its place modulo the tile (the print repeats)."""
    u, v, w, h = face
    n = PRINT_TEXELS
    canvas = np.zeros((3 * n, 3 * n, 3), np.uint8)  # drawn on a 3 x 3 copy about the tile, folded back onto it
    drawn = np.zeros((3 * n, 3 * n), np.uint8)
    cu, cv = n + u, n + v
    lw, lh = int(min(180, 0.3 * w)), int(min(90, 0.2 * h))
    x, y = int(cu - lw / 2), int(cv - 0.45 * h)  # between the upper corners' features
    cv2.rectangle(canvas, (x, y), (x + lw, y + lh), (235, 235, 228), -1)
    cv2.putText(
        canvas,
        f"ORU {int(rng.integers(100, 999))}",
        (x + 10, y + int(0.4 * lh)),
        cv2.FONT_HERSHEY_SIMPLEX,
        lh / 90.0,
        (20, 20, 20),
        2,
        cv2.LINE_AA,
    )
    for k in range(int((lw - 20) / 6)):
        if rng.random() < 0.55:
            bx = x + 10 + 6 * k
            cv2.rectangle(canvas, (bx, y + int(0.55 * lh)), (bx + 3, y + lh - 8), (15, 15, 15), -1)
    cv2.rectangle(drawn, (x, y), (x + lw, y + lh), 255, -1)
    text_scale = 0.3 * w / 180.0  # (the text about a third of the face wide, left of its middle)
    cv2.putText(
        canvas,
        "LIFT HERE",
        (int(cu - 0.46 * w), int(cv + 0.05 * h)),
        cv2.FONT_HERSHEY_DUPLEX,
        text_scale,
        ink,
        max(2, int(3 * text_scale)),
        cv2.LINE_AA,
    )
    cv2.putText(
        drawn,
        "LIFT HERE",
        (int(cu - 0.46 * w), int(cv + 0.05 * h)),
        cv2.FONT_HERSHEY_DUPLEX,
        text_scale,
        255,
        max(2, int(3 * text_scale)),
        cv2.LINE_AA,
    )
    for i in range(3):
        for j in range(3):
            block = drawn[j * n : (j + 1) * n, i * n : (i + 1) * n] > 0
            tile[block] = canvas[j * n : (j + 1) * n, i * n : (i + 1) * n][block]


def printed(mesh: trimesh.Trimesh) -> tuple[trimesh.Trimesh, np.ndarray]:
    """``mesh`` with a vertex per face corner and texture coordinates (n, 2): each face takes the print projected
    along the axis nearest its normal, ``TEXEL_MM`` mm a texel, repeating."""
    unmerged = trimesh.Trimesh(
        mesh.vertices[mesh.faces].reshape(-1, 3), np.arange(3 * len(mesh.faces)).reshape(-1, 3), process=False
    )
    axis = np.abs(mesh.face_normals).argmax(axis=1).repeat(3)
    v = unmerged.vertices
    keep = np.array([[1, 2], [0, 2], [0, 1]])[axis]  # the two coordinates across the face's main axis
    uv = np.take_along_axis(v, keep, axis=1) / (TEXEL_MM * PRINT_TEXELS)
    return unmerged, uv


def real_components(
    components: list[SceneItem], *, form_error_mm: float = WORKSHOP_FORM_ERROR_MM, seed: int = 0
) -> list[SceneItem]:
    """The cell's components as they really are: each with its form error and its print (fixtures such as the
    floor only printed). The CAD (``components``) is untouched."""
    real = []
    for k, item in enumerate(components):
        mesh = (
            form_error(item.mesh, form_error_mm, seed + k)
            if item.kind == "component" and form_error_mm > 0
            else item.mesh
        )
        mesh, uv = printed(mesh)
        # the print carries the colour: a textured surface is drawn white under it, as the renderer multiplies the two
        real.append(
            dataclasses.replace(
                item,
                mesh=mesh,
                color=(1.0, 1.0, 1.0),
                texture=print_tile(
                    item.color, seed + k, main_face_texel(item.mesh) if item.kind == "component" else None
                ),
                texture_coords=uv,
            )
        )
    return real


def make_less_kind(bed: TestBed, *, form_error_mm: float = WORKSHOP_FORM_ERROR_MM, seed: int = 0) -> None:
    """Turn ``bed`` into a workshop: its components as :func:`real_components` makes them (where they really are:
    the bed's own ``true_components`` when it has them) and its camera's look :func:`real_camera_look`."""
    where = bed.workcell.components if bed.true_components is None else bed.true_components
    bed.true_components = real_components(list(where), form_error_mm=form_error_mm, seed=seed)
    bed.camera_look = real_camera_look(bed.true_components)
