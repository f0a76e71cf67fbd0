"""Which of an object's feature points a camera sees, not hidden by the object itself: known answers on a cube."""

from __future__ import annotations

import numpy as np
import trimesh

from calib_core.look.in_view import seen_unhidden


def test_a_cube_s_near_corners_are_seen_and_its_far_corners_that_lie_behind_it_are_not():
    cube = trimesh.creation.box(extents=(100.0, 100.0, 100.0))
    obj2cam = np.eye(4)
    obj2cam[:3, 3] = [0.0, 0.0, 1000.0]  # the camera 950 mm in front of the face at z = -50 (the object's frame)
    near = np.array([[40.0, 40.0, -50.0], [-40.0, 10.0, -50.0]])  # on the face toward the camera
    far = np.array([[0.0, 0.0, 50.0], [30.0, -20.0, 50.0]])  # on the back face, straight behind the front one
    assert seen_unhidden(cube, np.vstack([near, far]), obj2cam).tolist() == [True, True, False, False]
    turned = obj2cam.copy()
    turned[:3, :3] = trimesh.transformations.rotation_matrix(np.pi, [0, 1, 0])[:3, :3]  # seen from behind
    assert seen_unhidden(cube, np.vstack([near, far]), turned).tolist() == [False, False, True, True]
