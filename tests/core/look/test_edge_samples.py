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
