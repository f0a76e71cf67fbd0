"""Which model edges the edge refinement samples: each edge once, and none that another edge crowds."""

from __future__ import annotations

import numpy as np
import trimesh

from calib_core.frames import make_transform
from calib_core.look.edge_samples import _clearance, _segment_keys, visible_segments


def test_a_crease_on_the_silhouette_is_sampled_once():
    box = trimesh.creation.box(extents=[100.0, 60.0, 20.0])
    obj2cam = make_transform(np.eye(3), [10.0, -5.0, 400.0])  # looking at one face, a little off-axis
    seg = visible_segments(box, obj2cam)
    keys = [k.tobytes() for k in _segment_keys(seg)]
    assert len(keys) == len(set(keys))
    # the face turned to the camera: its four edges, creases and the outline too, each listed once
    front = [k for k, s in zip(keys, seg) if np.allclose(s[:, 2], -10.0)]
    assert len(front) == 4


def test_a_key_is_the_same_both_ways():
    a, b = np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0])
    assert np.array_equal(_segment_keys(np.array([[a, b]])), _segment_keys(np.array([[b, a]])))
    # and two segments sharing one end, or the same ends shifted by a micrometre, are not the same
    c = b + [0.0, 0.0, 0.001]
    assert not np.array_equal(_segment_keys(np.array([[a, b]])), _segment_keys(np.array([[a, c]])))


def test_clearance_is_the_distance_along_the_normal_to_the_nearest_other_edge():
    ends = np.array(
        [
            [[0.0, 0.0], [100.0, 0.0]],  # the sample's own edge
            [[0.0, 2.5], [100.0, 2.5]],  # a parallel one 2.5 px away
            [[50.0, -5.0], [50.0, 5.0]],  # a crossing one, beside the sample, not across its normal
            [[0.0, -7.0], [30.0, -7.0]],  # a short parallel one, not across the second sample's normal
        ]
    )
    samples = np.array([[20.0, 0.0], [80.0, 0.0]])
    clearance = _clearance(samples, ends, np.array([0, 0]), np.array([True, True]))
    np.testing.assert_allclose(clearance, [2.5, 2.5])
    alone = _clearance(samples, ends[[0, 2]], np.array([0, 0]), np.array([True, True]))
    assert np.all(np.isinf(alone))
    below = _clearance(samples, ends[[0, 3]], np.array([0, 0]), np.array([True, True]))
    assert below[0] == 7.0 and np.isinf(below[1])


def test_a_fit_takes_its_rim_again_when_the_view_of_the_object_changes_not_when_it_rolls():
    """Known answers: the rim depends on the direction the object is seen from (its frame), and on the distance."""
    from scipy.spatial.transform import Rotation

    from calib_core.look.edge_refinement import perturbed, _seen_otherwise

    pose = make_transform(
        Rotation.from_euler("xyz", [20.0, -35.0, 10.0], degrees=True).as_matrix(), [30.0, -20.0, 800.0]
    )
    centre = np.array([5.0, 0.0, 12.0])
    seen_at = pose[:3, :3] @ centre + pose[:3, 3]  # where the camera sees the object's centre
    sight = seen_at / np.linalg.norm(seen_at)
    across = np.cross(sight, [0.0, 1.0, 0.0])
    across /= np.linalg.norm(across)

    def turned_about_centre(axis, deg):  # the camera turned round the object's centre
        R = Rotation.from_rotvec(np.radians(deg) * axis).as_matrix()
        out = pose.copy()
        out[:3, :3] = R @ pose[:3, :3]
        out[:3, 3] = R @ (pose[:3, 3] - seen_at) + seen_at
        return out

    assert not _seen_otherwise(pose, turned_about_centre(sight, 30.0), centre)  # a roll: the same rim
    assert not _seen_otherwise(pose, turned_about_centre(across, 0.7), centre)
    assert _seen_otherwise(pose, turned_about_centre(across, 1.3), centre)
    assert not _seen_otherwise(pose, perturbed(pose, np.r_[0.0, 0.0, 0.0, 0.015 * seen_at]), centre)  # 1.5 % nearer
    assert _seen_otherwise(pose, perturbed(pose, np.r_[0.0, 0.0, 0.0, 0.025 * seen_at]), centre)
    # a move across the line of sight turns the view by its angle at the object: 10 mm at 800 mm is 0.7 deg, 20 mm 1.4
    assert not _seen_otherwise(pose, perturbed(pose, np.r_[0.0, 0.0, 0.0, 10.0 * across]), centre)
    assert _seen_otherwise(pose, perturbed(pose, np.r_[0.0, 0.0, 0.0, 20.0 * across]), centre)


def test_no_sample_is_sought_on_a_mesh_whose_longest_edge_the_image_makes_too_short():
    """A bound, never under the truth: a box's longest edge (its faces' diagonal, 100 mm) seen at 1000 mm with 800 px
    focal is at most 80 px long on the axis; the bound adds half."""
    from calib_core.camera.intrinsics import Intrinsics
    from calib_core.camera.projection import project_points
    from calib_core.look.edge_samples import _longest_edge_px

    box = trimesh.creation.box(extents=[80.0, 60.0, 20.0])
    camera = Intrinsics(800.0, 800.0, 320.0, 240.0, 640, 480)
    pose = make_transform(np.eye(3), [0.0, 0.0, 1010.0])  # the nearest face at 1000 mm
    bound = _longest_edge_px(box, pose, camera)
    assert bound == 1.5 * 100.0 * 800.0 / 1000.0
    ends = project_points(box.vertices[box.edges_unique].reshape(-1, 3), pose, camera).reshape(-1, 2, 2)
    assert np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).max() <= bound
