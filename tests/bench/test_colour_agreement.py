"""The real-photo bench's check of an answer against the annotation by the scanned mesh's own colours: known answers
on a photo painted from those colours, and the page's counts on made-up rows."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from bench.colour_agreement import colour_agreement, seen_inside, vertex_grey
from bench.photo_runs import Row
from bench.truth_checks import colour_evidence
from calib_core.camera.intrinsics import Intrinsics
from calib_core.mesh_files import load_mesh

CAT = Path(__file__).resolve().parents[1] / "data" / "third_party" / "lmo" / "models" / "obj_000006.ply"
CAMERA = Intrinsics(572.4, 573.6, 325.3, 242.0, 640, 480)


def _painted(mesh, obj2cam: np.ndarray) -> np.ndarray:
    """A photo of the mesh in its own vertex colours on a mid-grey ground: each seen vertex's colour at its pixel,
    the gaps filled by a closing, lightly blurred."""
    uv, _ = seen_inside(mesh, obj2cam, CAMERA)
    X = np.asarray(mesh.vertices) @ obj2cam[:3, :3].T + obj2cam[:3, 3]
    order = np.argsort(-X[:, 2])  # far first: the near surface is painted over it
    image = np.full((CAMERA.height, CAMERA.width, 3), 128, np.uint8)
    px = np.round(uv[order]).astype(int)
    image[px[:, 1], px[:, 0]] = np.asarray(mesh.visual.vertex_colors)[order, :3]
    return cv2.GaussianBlur(cv2.morphologyEx(image, cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)), (0, 0), 0.7)


@pytest.fixture(scope="module")
def cat():
    mesh = load_mesh(CAT)
    pose = np.eye(4)
    pose[:3, :3] = cv2.Rodrigues(np.array([2.0, 0.4, -0.3]))[0]
    pose[:3, 3] = [10.0, -20.0, 800.0]
    return mesh, pose, _painted(mesh, pose)


def test_the_colours_agree_best_at_the_pose_the_photo_was_painted_at(cat):
    mesh, pose, photo = cat
    at_pose = colour_agreement(photo, mesh, pose, CAMERA)
    assert at_pose > 0.8
    for shift_mm in ((3.0, 0.0, 0.0), (0.0, -3.0, 0.0)):  # 2 px in the image
        moved = pose.copy()
        moved[:3, 3] += shift_mm
        assert colour_agreement(photo, mesh, moved, CAMERA) < at_pose - 0.05
    turned = pose.copy()
    turned[:3, :3] = cv2.Rodrigues(np.array([0.0, 0.0, np.radians(4.0)]))[0] @ pose[:3, :3]
    assert colour_agreement(photo, mesh, turned, CAMERA) < at_pose - 0.05


def test_a_mesh_without_vertex_colours_or_out_of_sight_has_no_agreement(cat):
    import trimesh

    mesh, pose, photo = cat
    plain = trimesh.creation.box((50.0, 50.0, 50.0))
    assert vertex_grey(plain) is None
    assert colour_agreement(photo, plain, pose, CAMERA) is None
    behind = pose.copy()
    behind[:3, 3] = [10.0, -20.0, -800.0]
    assert colour_agreement(photo, mesh, behind, CAMERA) is None


def _row(mspd_px: float, at_answer: float, at_truth: float, dataset: str = "lmo_dev", width: int = 640) -> Row:
    return Row(
        dataset,
        (10.0, 3.0),
        "k",
        "ok",
        1.0,
        mspd_px,
        1.0,
        1.0,
        1.0,
        100.0,
        0.5,
        width,
        colours_at=(at_answer, at_truth),
    )


def test_the_page_counts_which_pose_the_colours_agree_with_by_how_far_the_answer_is_off():
    rows = [_row(3.0, 0.5, 0.4), _row(7.0, 0.6, 0.3), _row(7.0, 0.3, 0.6), _row(7.0, 0.40, 0.41), _row(20.0, 0.1, 0.5)]
    rows.append(_row(np.inf, 0.1, 0.5))  # no answer: not counted
    rows.append(Row("lmo_dev", (10.0, 3.0), "k", "ok", 1.0, 7.0, 1.0, 1.0, 1.0, 100.0, 0.5, 640))  # no colours
    table = colour_evidence(rows)
    assert table[2:] == [
        "| lmo_dev | 0-5 px | 1 | 1 | 0 | 0 |",
        "| lmo_dev | 5-10 px | 3 | 1 | 1 | 1 |",
        "| lmo_dev | more than 10 px | 1 | 0 | 1 | 0 |",
    ]
    assert colour_evidence([]) == []


def test_a_wide_photo_s_answer_is_banded_at_640_px_width():
    """18 px off on a 1920 px photo is 6 px at 640 px width, where a wrong ``ok`` is counted too."""
    table = colour_evidence([_row(18.0, 0.6, 0.3, dataset="handal_dev", width=1920)])
    assert table[2:] == ["| handal_dev | 5-10 px | 1 | 1 | 0 | 0 |"]
