"""What ``videocal locate --overlay`` draws: each pose's outline in its colour (the prior red, the answer green, an
``uncertain`` answer's rival amber), a CAD part's creases with it and a scanned mesh's not. Checked against a box's
outline computed another way (the convex hull of its projected corners)."""

from __future__ import annotations

import cv2
import numpy as np
import trimesh

from app.cli.cmd_locate import _write_overlay
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look.located import Located

CAMERA = Intrinsics(600.0, 600.0, 320.0, 240.0, 640, 480)
BOX = trimesh.creation.box((80.0, 60.0, 40.0))
LEGEND_ROWS = 70
"""The overlay's top rows hold the legend (which colour is which): left out of the pixel checks."""
COLOURS = {"prior": (0, 0, 255), "answer": (0, 200, 0), "rival": (0, 170, 255)}  # BGR, as drawn


def _pose(x_mm: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = trimesh.transformations.euler_matrix(0.4, 0.3, 0.2)[:3, :3]
    pose[:3, 3] = (x_mm, 30.0, 900.0)
    return pose


def _drawn(tmp_path, rival: np.ndarray | None, creases: bool) -> np.ndarray:
    located = Located(
        "uncertain" if rival is not None else "ok", "", _pose(0.0), None, None, 1.0, 1.0, 60, rival_obj2cam=rival
    )
    photo = np.full((480, 640, 3), 128, np.uint8)
    path = tmp_path / "overlay.png"
    _write_overlay(path, photo, CAMERA, BOX, _pose(120.0), located, creases=creases)
    return cv2.imread(str(path))


def _pixels_of(picture: np.ndarray, colour) -> np.ndarray:
    """(n, 2) u, v of the pixels mostly of ``colour`` (anti-aliased lines blend into the grey), below the legend."""
    close = np.linalg.norm(picture.astype(float) - colour, axis=2) < 60
    close[:LEGEND_ROWS] = False
    v, u = np.nonzero(close)
    return np.column_stack([u, v]).astype(float)


def _off_hull_px(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """How far each pixel (n, 2) is from the outline of the box at ``pose``: its corners' convex hull in the image."""
    hull = cv2.convexHull(project_points(np.asarray(BOX.vertices), pose, CAMERA).astype(np.float32))
    return np.array([abs(cv2.pointPolygonTest(hull, (float(u), float(v)), True)) for u, v in points])


def _round_px(pose: np.ndarray) -> float:
    """The length of the box's outline at ``pose`` in the image, px."""
    hull = cv2.convexHull(project_points(np.asarray(BOX.vertices), pose, CAMERA).astype(np.float32))
    return cv2.arcLength(hull, True)


def test_each_pose_s_outline_is_drawn_in_its_colour_and_the_rival_too(tmp_path):
    rival = _pose(-120.0)
    picture = _drawn(tmp_path, rival, creases=False)
    for name, pose in (("prior", _pose(120.0)), ("answer", _pose(0.0)), ("rival", rival)):
        pixels = _pixels_of(picture, COLOURS[name])
        assert len(pixels) > 0.8 * _round_px(pose), name  # the whole outline
        assert np.percentile(_off_hull_px(pixels, pose), 95) < 1.5, name
    assert picture[:LEGEND_ROWS].std() > 0  # the legend is written


def test_no_rival_is_drawn_for_an_answer_without_one(tmp_path):
    picture = _drawn(tmp_path, None, creases=False)
    assert len(_pixels_of(picture, COLOURS["rival"])) == 0
    assert len(_pixels_of(picture, COLOURS["answer"])) > 0.8 * _round_px(_pose(0.0))


def test_a_cad_part_s_creases_are_drawn_inside_its_outline_a_scanned_mesh_s_are_not(tmp_path):
    """With creases the box's inner edges show inside its outline; without, every drawn pixel is on the outline."""
    outline_only = _off_hull_px(_pixels_of(_drawn(tmp_path, None, creases=False), COLOURS["answer"]), _pose(0.0))
    with_creases = _off_hull_px(_pixels_of(_drawn(tmp_path, None, creases=True), COLOURS["answer"]), _pose(0.0))
    assert (outline_only > 3.0).sum() == 0
    assert (with_creases > 3.0).sum() > 100
