"""The camera poses the edge refinement starts from: their geometry by known answers, and the ranking
on a synthetic edge image whose true pose is known."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.look.edge_alignment import edge_distance_map
from calib_core.look.pose_hypotheses import (
    TRUNCATE_PX,
    moved_cameras,
    object_turned,
    rank_starts,
    turn_moves_px,
    turned_camera,
)

INTRINSICS = Intrinsics(fu=1120.0, fv=1116.0, cx=640.0, cy=480.0, width=1280, height=960)


def _pose(rotvec_deg, t_mm) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.radians(rotvec_deg)).as_matrix()
    T[:3, 3] = t_mm
    return T


def _centre_in_object(obj2cam: np.ndarray) -> np.ndarray:
    return -obj2cam[:3, :3].T @ obj2cam[:3, 3]


def test_a_moved_camera_s_centre_moves_by_the_shift_in_its_own_axes_and_rolls_about_its_axis():
    obj2cam = _pose([10, -20, 5], [15, -8, 300])
    shifts = np.array([[5.0, 0, 0], [0, -7.0, 3.0], [0, 0, 0]])
    moved = moved_cameras(obj2cam, shifts, np.array([0.0, 0.0, 3.0]))
    for T, shift in zip(moved, shifts):
        # the camera's centre, in the object frame, moved by the shift expressed in the camera's axes
        expected = _centre_in_object(obj2cam) + obj2cam[:3, :3].T @ shift
        assert np.allclose(_centre_in_object(T), expected, atol=1e-9)
    roll = moved[2][:3, :3] @ obj2cam[:3, :3].T
    assert np.allclose(Rotation.from_matrix(roll).as_rotvec(), [0, 0, np.radians(3.0)], atol=1e-12)


def test_a_turned_camera_moves_the_image_by_the_shift_where_it_is_measured():
    obj2cam = _pose([0, 0, 0], [0, 0, 400])
    point = np.array([[0.0, 0.0, 0.0]])  # on the optical axis: the first-order turn is exact to second order there
    before = project_points(point, obj2cam, INTRINSICS)[0]
    after = project_points(point, turned_camera(obj2cam, np.array([12.0, -7.0]), INTRINSICS), INTRINSICS)[0]
    assert np.allclose(after - before, [12.0, -7.0], atol=0.05)
    assert np.allclose(
        _centre_in_object(turned_camera(obj2cam, np.array([12.0, -7.0]), INTRINSICS)), _centre_in_object(obj2cam)
    )


def _edge_image(mesh, obj2cam) -> np.ndarray:
    """A grey image (h, w) with the box's outline drawn at ``obj2cam``: what its edges look like."""
    image = np.full((INTRINSICS.height, INTRINSICS.width), 90, np.uint8)
    for a, b in mesh.vertices[mesh.edges_unique]:
        uv = project_points(np.array([a, b]), obj2cam, INTRINSICS)
        cv2.line(image, tuple(np.int32(uv[0])), tuple(np.int32(uv[1])), 230, 2)
    return image


def test_the_best_start_is_near_the_true_pose_where_a_two_d_shift_is_not():
    """A box 160 mm deep seen from 180 mm: the camera 12 mm and 1 deg off moves its near and far faces
    by different amounts. The ranking must put a start where the edges nearly lie on the image's."""
    mesh = trimesh.creation.box(extents=[180.0, 120.0, 160.0])
    truth = _pose([0, 0, 0], [0, 0, 260.0])
    model = moved_cameras(truth, np.array([[12.0, -6.0, 4.0]]), np.array([1.0]))[0]
    model = turned_camera(model, np.array([-15.0, 10.0]), INTRINSICS)
    distance = edge_distance_map(_edge_image(mesh, truth), TRUNCATE_PX)
    samples = np.concatenate(
        [a + (b - a) * np.linspace(0.05, 0.95, 12)[:, None] for a, b in mesh.vertices[mesh.edges_unique]]
    )

    def miss_px(pose):
        return float(
            np.mean(
                np.linalg.norm(
                    project_points(samples, pose, INTRINSICS) - project_points(samples, truth, INTRINSICS), axis=1
                )
            )
        )

    assert miss_px(model) > 40.0
    starts = rank_starts(distance, INTRINSICS, samples, model, reach_mm=20.0, reach_deg=1.5)
    assert 1 <= len(starts) <= 3
    # within a cell of the grid (5 mm of the centre's move is up to 15 px on the near face, a turn's
    # step 10 px): close enough for the edge refinement, a quarter of the model's miss or less
    assert miss_px(starts[0]) < min(12.0, miss_px(model) / 4), [miss_px(s) for s in starts]
    # the others differ from it in the image
    for s in starts[1:]:
        assert (
            np.mean(
                np.linalg.norm(
                    project_points(samples, s, INTRINSICS) - project_points(samples, starts[0], INTRINSICS), axis=1
                )
            )
            > 5.0
        )


def test_an_object_turned_keeps_its_centre_and_turns_about_the_camera_s_axes_across_the_line_of_sight():
    poses = np.stack([_pose([10, -20, 5], [15, -8, 300]), _pose([0, 30, 0], [-40, 5, 650])])
    grid = np.array([[1.0, 2.0, 3.0, 0.5], [0.0, 0.0, 0.0, 0.0]])
    centre = np.array([12.0, -4.0, 30.0])
    turned, turned_grid = object_turned(poses, grid, centre, 4.0)
    assert turned.shape == (18, 4, 4) and turned_grid.shape == (18, 6)
    assert np.array_equal(turned[:2], poses) and np.array_equal(turned_grid[:2, :4], grid)  # the unturned first
    for k, (T, row) in enumerate(zip(turned, turned_grid)):
        P = poses[k % 2]
        # the centre stays where the camera saw it
        assert np.allclose(T[:3, :3] @ centre + T[:3, 3], P[:3, :3] @ centre + P[:3, 3], atol=1e-9)
        # the turn, in the camera's frame, is the grid's two angles about its x and y axes
        turn = Rotation.from_matrix(T[:3, :3] @ P[:3, :3].T).as_rotvec()
        assert np.allclose(np.degrees(turn), [row[4], row[5], 0.0], atol=1e-9)
        assert np.array_equal(row[:4], grid[k % 2])
    assert sorted({(a, b) for a, b in turned_grid[:, 4:]}) == [(a, b) for a in (-4, 0, 4) for b in (-4, 0, 4)]


def test_with_the_object_s_turn_searched_a_long_part_turned_from_its_prior_gets_a_start_near_it():
    """A tool-like bar 240 mm long, pointing 55 deg away from the camera 350 mm off, its prior turned 6 deg about an
    axis across the line of sight through its centre (an error of the object itself, as a photo's prior is): its
    edges lie some 26 px off, and no start of the camera's grid (its centre moved up to 10 mm, its line of sight
    turned up to 10 deg) lays them on the image: a turn of the object changes its outline's shape. Searched, the
    object's own turn does."""
    mesh = trimesh.creation.box(extents=[240.0, 24.0, 16.0])
    truth = _pose([0, 55, 10], [10, 0, 350.0])
    model = truth.copy()
    model[:3, :3] = Rotation.from_rotvec(np.radians([0.0, 6.0, 0.0])).as_matrix() @ truth[:3, :3]  # about its centre
    distance = edge_distance_map(_edge_image(mesh, truth), TRUNCATE_PX)
    samples = np.concatenate(
        [a + (b - a) * np.linspace(0.05, 0.95, 12)[:, None] for a, b in mesh.vertices[mesh.edges_unique]]
    )

    def miss_px(pose):
        seen = project_points(samples, pose, INTRINSICS) - project_points(samples, truth, INTRINSICS)
        return float(np.mean(np.linalg.norm(seen, axis=1)))

    assert miss_px(model) > 20.0
    camera_only = rank_starts(distance, INTRINSICS, samples, model, reach_mm=10.0, reach_deg=10.0)
    with_turns = rank_starts(distance, INTRINSICS, samples, model, reach_mm=10.0, reach_deg=10.0, object_turn_deg=5.0)
    assert min(miss_px(s) for s in camera_only) > 15.0
    assert miss_px(with_turns[0]) < 4.0, [miss_px(s) for s in with_turns]


def test_a_turn_moves_a_point_seen_face_on_little_and_one_pointing_away_by_its_arc():
    obj2cam = _pose([0, 0, 0], [0, 0, 500.0])
    face_on = np.array([[100.0, 0.0, 0.0], [-100.0, 0.0, 0.0], [0.0, 50.0, 0.0], [0.0, -50.0, 0.0]])
    pointing_away = np.array([[0.0, 0.0, 100.0], [0.0, 0.0, -100.0]])
    arc = np.radians(5.0) * 100.0 * 1120.0 / 500.0  # 19.5 px, to first order
    # face on, a turn across the line of sight moves the ends along it: foreshortening, a quarter of the arc
    assert 0.1 * arc < turn_moves_px(face_on, obj2cam, INTRINSICS, 5.0) < 0.3 * arc
    # pointing away, the near end swings across the image: turned about both axes at once (7.1 deg) and 100 mm
    # nearer the camera, sqrt(2) x 500 / 400 times the arc
    assert turn_moves_px(pointing_away, obj2cam, INTRINSICS, 5.0) == pytest.approx(
        1120.0 * 100.0 * np.sin(np.radians(5.0) * np.sqrt(2.0)) / 400.0, rel=0.03
    )


def test_a_small_part_far_off_is_ranked_as_without_the_object_s_turn():
    """A 30 mm cube a metre off, turned 1 deg: its samples move under a pixel, no candidate more than the camera's
    grid gives; the ranking is the camera's alone."""
    mesh = trimesh.creation.box(extents=[30.0, 30.0, 30.0])
    truth = _pose([20, 30, 0], [40, -20, 1000.0])
    model = moved_cameras(truth, np.array([[4.0, -3.0, 5.0]]), np.array([0.5]))[0]
    distance = edge_distance_map(_edge_image(mesh, truth), TRUNCATE_PX)
    samples = np.concatenate(
        [a + (b - a) * np.linspace(0.05, 0.95, 12)[:, None] for a, b in mesh.vertices[mesh.edges_unique]]
    )
    assert turn_moves_px(samples, model, INTRINSICS, 1.0) < 1.0
    plain = rank_starts(distance, INTRINSICS, samples, model, reach_mm=10.0, reach_deg=1.0)
    turned = rank_starts(distance, INTRINSICS, samples, model, reach_mm=10.0, reach_deg=1.0, object_turn_deg=1.0)
    assert len(plain) == len(turned) and all(np.array_equal(a, b) for a, b in zip(plain, turned))
