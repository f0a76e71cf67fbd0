"""A hole through an object's silhouette is outline too: a torus seen along its axis fills a ring, and the ring's inner
edge (where the background shows through) holds samples as its outer edge does, with the background on the hole's
side. Known answers from the torus's own radii."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look.edge_samples import edge_model
from calib_core.look.outline import HOLE_MIN_PX2, outline_samples

CAMERA = Intrinsics(800.0, 800.0, 320.0, 240.0, 640, 480)
MAJOR_MM, MINOR_MM = 40.0, 12.0
DISTANCE_MM = 500.0


def _facing(distance_mm: float = DISTANCE_MM, tilt_deg: float = 0.0) -> np.ndarray:
    """The torus's axis along the line of sight (turned ``tilt_deg`` about the image's x axis), ``distance_mm`` away."""
    a = np.radians(tilt_deg)
    obj2cam = np.eye(4)
    obj2cam[:3, :3] = [[1.0, 0.0, 0.0], [0.0, np.cos(a), -np.sin(a)], [0.0, np.sin(a), np.cos(a)]]
    obj2cam[:3, 3] = (10.0, -5.0, distance_mm)
    return obj2cam


def _torus(minor_mm: float = MINOR_MM) -> trimesh.Trimesh:
    return trimesh.creation.torus(MAJOR_MM, minor_mm, major_sections=96, minor_sections=48)


@pytest.mark.parametrize("tilt_deg", [0.0, 20.0])
def test_a_torus_s_hole_holds_outline_samples_on_its_inner_rim(tilt_deg):
    """Seen along its axis a torus's rim is two circles, R + r and R - r from the axis (mm): the samples split into
    those two, the inner one holding about its share of the samples (its length in the image over the sample step).
    Turned 20 deg the rims are no longer circles of the mesh, but every sample still lies on one of the two sides of
    the ring."""
    torus = _torus()
    outline = outline_samples(torus, _facing(tilt_deg=tilt_deg), CAMERA, step_px=4.0)
    radius = np.linalg.norm(outline.points_mm[:, :2], axis=1)
    inner = radius < MAJOR_MM
    assert inner.any(), "no sample on the hole's rim"
    if tilt_deg == 0.0:
        np.testing.assert_allclose(radius[inner], MAJOR_MM - MINOR_MM, atol=0.5)
        np.testing.assert_allclose(radius[~inner], MAJOR_MM + MINOR_MM, atol=0.5)
        inner_length_px = 2 * np.pi * CAMERA.fu * (MAJOR_MM - MINOR_MM) / DISTANCE_MM
        outer_length_px = 2 * np.pi * CAMERA.fu * (MAJOR_MM + MINOR_MM) / DISTANCE_MM
        assert inner.sum() == pytest.approx(inner_length_px / 4.0, rel=0.15)
        assert (~inner).sum() == pytest.approx(outer_length_px / 4.0, rel=0.15)
    else:
        # the inner rim of a turned torus lies on the tube's inner half, the outer on its outer half
        assert (radius[inner] < MAJOR_MM - 0.5 * MINOR_MM).all()
        assert (radius[~inner] > MAJOR_MM + 0.5 * MINOR_MM).all()


def test_the_hole_s_samples_have_the_background_on_the_hole_s_side():
    """Each sample's outward side (where the object is not) points into the hole for the inner rim and away from the
    ring for the outer: 3 px that way a pixel is nearer the ring's centre than the inner rim, or further than the
    outer."""
    torus = _torus()
    obj2cam = _facing()
    model = edge_model(torus, obj2cam, CAMERA, whole_outline=True)
    uv = project_points(model.points, obj2cam, CAMERA)
    d = project_points(model.far, obj2cam, CAMERA) - uv
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    normals = np.column_stack([-d[:, 1], d[:, 0]])
    assert (model.outward != 0).all()
    beside = uv + 3.0 * model.outward[:, None] * normals
    centre = project_points(np.zeros((1, 3)), obj2cam, CAMERA)[0]
    from_centre = np.linalg.norm(beside - centre, axis=1)
    inner = np.linalg.norm(model.points[:, :2], axis=1) < MAJOR_MM
    assert inner.any() and (~inner).any()
    scale = CAMERA.fu / DISTANCE_MM
    assert (from_centre[inner] < (MAJOR_MM - MINOR_MM) * scale).all()
    assert (from_centre[~inner] > (MAJOR_MM + MINOR_MM) * scale).all()


def test_a_hole_under_the_least_area_is_not_outline():
    """A hole of under :data:`HOLE_MIN_PX2` holds a handful of samples the photo barely resolves: not outline. A torus
    whose hole is 1.5 mm across its radius (at 500 mm, 2.4 px: 18 px^2) gives its outer rim only; one of 3 mm (4.8 px:
    72 px^2) its hole's rim as well."""
    small = 800.0 * 1.5 / DISTANCE_MM
    assert np.pi * small**2 < HOLE_MIN_PX2 < np.pi * (2 * small) ** 2
    for hole_mm, has_inner in ((1.5, False), (3.0, True)):
        outline = outline_samples(_torus(MAJOR_MM - hole_mm), _facing(), CAMERA, step_px=4.0)
        radius = np.linalg.norm(outline.points_mm[:, :2], axis=1)
        assert (radius < MAJOR_MM).any() == has_inner, hole_mm
