"""The lens map a render is distorted through: each pixel of the real image samples the ideal render where the lens
sends its ray (checked against the projection it is made from), made once per camera and shared read-only."""

import numpy as np
import pytest

from calib_core.camera.distortion_map import distortion_map
from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, unproject

BARREL = Intrinsics(1100.0, 1098.0, 652.0, 471.0, 1280, 960, distortion=(-0.21, 0.08, 0.001, -0.0007, -0.01))


def test_each_pixel_samples_the_ideal_render_where_the_lens_sends_its_ray():
    lens_map = distortion_map(BARREL)
    rng = np.random.default_rng(3)
    pixels = np.column_stack([rng.integers(0, 1280, 200), rng.integers(0, 960, 200)]).astype(float)
    ray = unproject(pixels, BARREL, undistort=True)
    shift = np.array([lens_map.ideal.cx - BARREL.cx, lens_map.ideal.cy - BARREL.cy])
    expected = project(ray, BARREL, distort=False) + shift
    got = np.column_stack(
        [
            lens_map.map_x[pixels[:, 1].astype(int), pixels[:, 0].astype(int)],
            lens_map.map_y[pixels[:, 1].astype(int), pixels[:, 0].astype(int)],
        ]
    )
    np.testing.assert_allclose(got, expected, atol=1e-3)
    # the ideal canvas holds every sample: barrel distortion's corners reach beyond the image
    assert lens_map.map_x.min() >= 0 and lens_map.map_x.max() <= lens_map.ideal.width - 1
    assert lens_map.map_y.min() >= 0 and lens_map.map_y.max() <= lens_map.ideal.height - 1
    # and a point of the ideal image comes back through the lens to where the camera sees it
    corner = np.array([[3.0, 5.0]])
    back = project(unproject(corner, BARREL, undistort=True), BARREL)
    np.testing.assert_allclose(back, corner, atol=1e-6)


def test_one_map_a_camera_shared_read_only():
    first = distortion_map(BARREL)
    same_camera = Intrinsics(1100.0, 1098.0, 652.0, 471.0, 1280, 960, distortion=(-0.21, 0.08, 0.001, -0.0007, -0.01))
    assert distortion_map(same_camera) is first  # made once: the window's warm-up makes it for the first Find points
    other = distortion_map(BARREL.scaled(0.5))
    assert other is not first and other.map_x.shape == (480, 640)
    with pytest.raises(ValueError):
        first.map_x[0, 0] = 0.0
