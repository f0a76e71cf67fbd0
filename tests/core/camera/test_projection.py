import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from calib_core import frames
from calib_core.camera import Intrinsics, project, project_points, undistort_pixels, unproject

INTR = Intrinsics(1100.0, 1080.0, 652.3, 471.8, 1280, 960, (-0.21, 0.09, 0.0012, -0.0008, -0.015))


def _points(rng, n=200):
    return rng.uniform([-300, -220, 400], [300, 220, 1200], (n, 3))


def test_project_matches_opencv_with_distortion():
    p = _points(np.random.default_rng(0))
    ours = project(p, INTR)
    ref = cv2.projectPoints(p, np.zeros(3), np.zeros(3), INTR.K, INTR.dist_coeffs)[0].reshape(-1, 2)
    np.testing.assert_allclose(ours, ref, atol=1e-9)


def test_project_without_distortion_is_pinhole():
    uv = project([[100.0, -50.0, 1000.0]], INTR, distort=False)[0]
    np.testing.assert_allclose(uv, [1100 * 0.1 + 652.3, 1080 * -0.05 + 471.8])


def test_optical_axis_hits_principal_point():
    np.testing.assert_allclose(project([[0.0, 0.0, 500.0]], INTR)[0], [INTR.cx, INTR.cy])


def test_points_behind_camera_give_nan():
    uv = project([[0, 0, -10.0], [0, 0, 0.0], [1, 1, 10.0]], INTR)
    assert np.isnan(uv[0]).all() and np.isnan(uv[1]).all() and np.isfinite(uv[2]).all()


def test_unproject_round_trip_with_distortion():
    p = _points(np.random.default_rng(3))
    back = unproject(project(p, INTR), INTR, depth_mm=p[:, 2])
    np.testing.assert_allclose(back, p, atol=1e-6)


def test_undistort_pixels_equals_ideal_projection():
    p = _points(np.random.default_rng(4))
    np.testing.assert_allclose(undistort_pixels(project(p, INTR), INTR), project(p, INTR, distort=False), atol=1e-6)


def test_project_points_applies_pose():
    obj2cam = frames.transform_from_xyz_rpy([10, 20, 800], [5, -3, 40])
    p_obj = _points(np.random.default_rng(5), 20) - [0, 0, 800]
    rvec, _ = cv2.Rodrigues(obj2cam[:3, :3])
    ref = cv2.projectPoints(p_obj, rvec, obj2cam[:3, 3], INTR.K, INTR.dist_coeffs)[0].reshape(-1, 2)
    np.testing.assert_allclose(project_points(p_obj, obj2cam, INTR), ref, atol=1e-8)


@settings(max_examples=40, deadline=None)
@given(u=st.floats(0, 1279), v=st.floats(0, 959), z=st.floats(100, 5000))
def test_unproject_then_project_is_identity(u, v, z):
    p = unproject([[u, v]], INTR, depth_mm=z)
    np.testing.assert_allclose(project(p, INTR)[0], [u, v], atol=1e-6)


def test_contains_uses_pixel_centres():
    inside = INTR.contains(np.array([[-0.5, -0.5], [1279.5, 959.5], [-0.6, 10], [10, 959.6]]))
    assert inside.tolist() == [True, True, False, False]


def test_scaled_keeps_rays():
    half = INTR.without_distortion().scaled(0.5)
    p = _points(np.random.default_rng(6), 10)
    full_px = project(p, INTR.without_distortion())
    np.testing.assert_allclose(project(p, half), (full_px + 0.5) * 0.5 - 0.5, atol=1e-9)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"fu": 0.0}, "focal lengths must be positive"),
        ({"fv": -5.0}, "focal lengths must be positive"),
        ({"cx": float("nan")}, "cx must be finite"),
        ({"fu": 1e23, "fv": 1e23}, "fu = 1e\\+23 px is no camera's"),
        ({"cy": -3e7}, "cy = -3e\\+07 px is no camera's"),
        ({"width": 0}, "width must be a positive whole number"),
        ({"distortion": (0.1, 0.2)}, "distortion needs 5 values"),
    ],
)
def test_bad_intrinsics(kwargs, message):
    base = dict(fu=800.0, fv=800.0, cx=320.0, cy=240.0, width=640, height=480)
    base.update(kwargs)
    with pytest.raises(ValueError, match=message):
        Intrinsics(**base)


def test_intrinsics_dict_round_trip_and_errors():
    assert Intrinsics.from_dict(INTR.to_dict()) == INTR
    with pytest.raises(ValueError, match="missing field.*fv"):
        Intrinsics.from_dict({"fu": 1, "cx": 1, "cy": 1, "width": 2, "height": 2})
    with pytest.raises(ValueError, match="'fu' must be a number"):
        Intrinsics.from_dict({**INTR.to_dict(), "fu": "800"})
    with pytest.raises(ValueError, match="unknown field.*focal"):
        Intrinsics.from_dict({**INTR.to_dict(), "focal": 3})
