import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from calib_core import frames

angles = st.floats(-179.0, 179.0)
coords = st.floats(-2000.0, 2000.0)


def _random_transform(rng):
    return frames.make_transform(Rotation.random(random_state=rng).as_matrix(), rng.uniform(-1000, 1000, 3))


def test_invert_and_concat_round_trip():
    rng = np.random.default_rng(1)
    a2b, b2c = _random_transform(rng), _random_transform(rng)
    a2c = frames.concat(a2b, b2c)
    p_a = rng.uniform(-500, 500, (10, 3))
    np.testing.assert_allclose(frames.apply(a2c, p_a), frames.apply(b2c, frames.apply(a2b, p_a)), atol=1e-9)
    np.testing.assert_allclose(frames.concat(a2c, frames.invert(a2c)), np.eye(4), atol=1e-12)
    np.testing.assert_allclose(frames.invert(a2b), np.linalg.inv(a2b), atol=1e-9)


def test_xyz_rpy_known_answer():
    # yaw 90 deg: x axis of the part points along +y of the base
    m = frames.transform_from_xyz_rpy([100, 200, 300], [0, 0, 90])
    np.testing.assert_allclose(frames.apply(m, [1, 0, 0]), [100, 201, 300], atol=1e-12)
    # fixed-axis XYZ: roll applied first, then pitch, then yaw (URDF rpy)
    m = frames.transform_from_xyz_rpy([0, 0, 0], [90, 0, 90])
    np.testing.assert_allclose(frames.apply(m, [0, 1, 0]), [0, 0, 1], atol=1e-12)


@settings(max_examples=50, deadline=None)
@given(x=coords, y=coords, z=coords, r=angles, p=st.floats(-89.0, 89.0), yw=angles)
def test_xyz_rpy_round_trip(x, y, z, r, p, yw):
    m = frames.transform_from_xyz_rpy([x, y, z], [r, p, yw])
    xyz, rpy = frames.xyz_rpy_from_transform(m)
    np.testing.assert_allclose(frames.transform_from_xyz_rpy(xyz, rpy), m, atol=1e-9)


def test_pose_difference_reconstructs_actual():
    rng = np.random.default_rng(2)
    model = _random_transform(rng)
    delta = frames.transform_from_rotvec_deg([0.2, -0.3, 0.1], [1.5, -2.0, 0.7])
    actual = model.copy()
    actual[:3, :3] = delta[:3, :3] @ model[:3, :3]
    actual[:3, 3] = model[:3, 3] + delta[:3, 3]
    d_mm, rv_deg = frames.pose_difference(actual, model)
    np.testing.assert_allclose(d_mm, [1.5, -2.0, 0.7], atol=1e-9)
    np.testing.assert_allclose(rv_deg, [0.2, -0.3, 0.1], atol=1e-9)


def test_rotation_angle_deg():
    assert frames.rotation_angle_deg(frames.transform_from_rotvec_deg([0, 0, 30])[:3, :3]) == pytest.approx(30.0)
    assert frames.rotation_angle_deg(np.eye(3)) == 0.0


def test_check_transform_names_the_problem():
    with pytest.raises(ValueError, match="flange2base: expected a 4x4"):
        frames.check_transform(np.eye(3), name="flange2base")
    bad = np.eye(4)
    bad[0, 0] = 2
    with pytest.raises(ValueError, match="not a proper rotation"):
        frames.check_transform(bad)
    bad = np.eye(4)
    bad[1, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        frames.check_transform(bad)


def test_skew_is_cross_product():
    a, b = np.array([1.0, -2.0, 3.0]), np.array([0.5, 4.0, -1.0])
    np.testing.assert_allclose(frames.skew(a) @ b, np.cross(a, b))
