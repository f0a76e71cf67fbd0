"""The edge refinement's Jacobian: its chain rule against central differences of the whole pose."""

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.look.edge_refinement import perturbed, normal_jacobian
from scipy.spatial.transform import Rotation


def test_the_normal_jacobian_matches_central_differences_of_the_pose_through_a_distorting_lens():
    rng = np.random.default_rng(3)
    intrinsics = Intrinsics(1100.0, 1090.0, 650.0, 470.0, 1280, 960, distortion=(-0.18, 0.07, 0.001, -0.0008, 0.0))
    obj2cam = make_transform(Rotation.from_rotvec([0.3, -0.2, 0.1]).as_matrix(), [20.0, -15.0, 250.0])
    points = rng.uniform(-60.0, 60.0, (30, 3))
    normals = rng.normal(size=(30, 2))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    J = normal_jacobian(points, obj2cam, normals, intrinsics)
    numeric = np.empty_like(J)
    for k in range(6):
        step = np.zeros(6)
        step[k] = 1e-6 if k < 3 else 1e-4
        plus = project_points(points, perturbed(obj2cam, step), intrinsics)
        minus = project_points(points, perturbed(obj2cam, -step), intrinsics)
        numeric[:, k] = np.einsum("ij,ij->i", (plus - minus) / (2 * step[k]), normals)
    assert np.allclose(J, numeric, rtol=1e-5, atol=1e-4 * np.abs(numeric).max())
    # and a small motion predicts the offsets it makes (first order)
    xi = np.array([2e-4, -1e-4, 3e-4, 0.05, -0.03, 0.1])
    moved = np.einsum(
        "ij,ij->i",
        project_points(points, perturbed(obj2cam, xi), intrinsics) - project_points(points, obj2cam, intrinsics),
        normals,
    )
    assert np.allclose(J @ xi, moved, atol=2e-3)
