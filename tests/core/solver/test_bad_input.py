"""Every bad input gives a specific ValueError subclass that names the points involved."""

import numpy as np
import pytest

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from calib_core.solver import (
    DegenerateGeometryError,
    DuplicatePointsError,
    InvalidIntrinsicsError,
    MismatchedPointsError,
    NonFiniteInputError,
    PointsBehindCameraError,
    SolveStatus,
    TooFewPointsError,
    solve_pose,
    solve_pose_batch,
)

from calib_core.solver.errors import named_points
from tests.core.solver.scenes import GRIPPER_CAMERA, pixels, random_points, random_pose

RNG = np.random.default_rng(0)
TRUTH = random_pose(RNG)
P = random_points(RNG, 5)
UV = pixels(P, TRUTH)


def test_too_few_points():
    with pytest.raises(TooFewPointsError, match="2 point pairs given, at least 3"):
        solve_pose(P[:2], UV[:2], GRIPPER_CAMERA)
    with pytest.raises(TooFewPointsError, match="at least 4 needed .the focal lengths"):
        solve_pose(P[:3], UV[:3], GRIPPER_CAMERA, estimate_focal=True)


def test_mismatched_lengths_and_shapes():
    with pytest.raises(MismatchedPointsError, match="5 3D points but 4 2D points"):
        solve_pose(P, UV[:4], GRIPPER_CAMERA)
    with pytest.raises(MismatchedPointsError, match="points_2d"):
        solve_pose(P, UV[:, :1], GRIPPER_CAMERA)
    with pytest.raises(MismatchedPointsError, match="points_3d"):
        solve_pose([[1, 2, 3], [4, 5]], UV[:2], GRIPPER_CAMERA)


def test_non_finite_values_name_the_point():
    uv = UV.copy()
    uv[3, 1] = np.nan
    with pytest.raises(NonFiniteInputError, match="point 4") as info:
        solve_pose(P, uv, GRIPPER_CAMERA)
    assert info.value.points == (3,)
    p = P.copy()
    p[0, 0] = np.inf
    with pytest.raises(NonFiniteInputError, match="point 1"):
        solve_pose(p, UV, GRIPPER_CAMERA)


def test_one_3d_point_at_two_pixels_is_allowed_and_a_disagreement_is_named():
    P2, UV2 = np.vstack([P, P[1]]), np.vstack([UV, UV[1] + [0.3, -0.2]])  # picked twice, within the noise
    again = solve_pose(P2, UV2, GRIPPER_CAMERA)
    assert again.status.value == "ok" and not any("same 3D point" in w for w in again.warnings)
    UV2[-1] = UV[1] + [6.0, 0.0]
    off = solve_pose(P2, UV2, GRIPPER_CAMERA)
    assert any(f"point 2 and point {len(P) + 1} are the same 3D point picked 6.0 px apart" in w for w in off.warnings)
    # one pair given twice is counted once, the repeat named and reported like its first
    twice = solve_pose(np.vstack([P[:4], P[1]]), np.vstack([UV[:4], UV[1]]), GRIPPER_CAMERA)
    once = solve_pose(P[:4], UV[:4], GRIPPER_CAMERA)
    assert twice.status is once.status and np.allclose(twice.obj2cam, once.obj2cam)
    assert (
        "1 pair given again (the same 3D point at the same pixel), each counted once: point 5 = point 2"
        in twice.warnings
    )
    assert twice.residuals_px.shape == (5, 2) and np.array_equal(twice.residuals_px[4], twice.residuals_px[1])
    # in the window's numbers, and so is every message of the solve on the distinct pairs
    P8 = random_points(np.random.default_rng(8), 8)
    uv = pixels(P8, TRUTH)
    uv[2] += [40.0, 0.0]  # a mis-click on the third pair
    with named_points("pair", [9, 10, 11, 12, 13, 14, 15, 16, 17]):
        named = solve_pose(np.vstack([P8, P8[1]]), np.vstack([uv, uv[1]]), GRIPPER_CAMERA)
    assert "each counted once: pair 17 = pair 10" in named.warnings[0]
    assert named.status is SolveStatus.FAILED and "pair 11 fits worst" in named.reason, named.reason


def test_two_points_at_one_pixel_name_both():
    uv = UV.copy()
    uv[2] = uv[0]
    with pytest.raises(DuplicatePointsError, match="point 1 and point 3 have the same pixel"):
        solve_pose(P, uv, GRIPPER_CAMERA)


def test_collinear_points():
    line = np.outer(np.arange(5.0), [10.0, 5.0, 2.0])
    with pytest.raises(DegenerateGeometryError, match="collinear"):
        solve_pose(line, UV, GRIPPER_CAMERA)


def test_prior_with_points_behind_the_camera():
    behind = make_transform(np.eye(3), [0.0, 0.0, -500.0])
    with pytest.raises(PointsBehindCameraError, match="prior pose puts points 1, 2, 3, 4, 5 at or behind"):
        solve_pose(P, UV, GRIPPER_CAMERA, prior=behind)


def test_non_positive_focal_length():
    bad = Intrinsics.__new__(Intrinsics)
    object.__setattr__(bad, "fu", -5.0)
    object.__setattr__(bad, "fv", 1000.0)
    with pytest.raises(InvalidIntrinsicsError, match="fu must be a positive focal length"):
        solve_pose(P, UV, bad)
    with pytest.raises(ValueError, match="focal lengths must be positive"):
        Intrinsics(0.0, 1000.0, 320, 240, 640, 480)


def test_unknown_model_and_bad_sigma():
    with pytest.raises(ValueError, match="model must be one of"):
        solve_pose(P, UV, GRIPPER_CAMERA, model="fisheye")
    with pytest.raises(ValueError, match="sigma_px"):
        solve_pose(P, UV, GRIPPER_CAMERA, sigma_px=-1.0)


def test_batch_shapes_and_values_are_checked():
    with pytest.raises(MismatchedPointsError):
        solve_pose_batch(P, UV, GRIPPER_CAMERA)
    bad = np.stack([UV, UV])
    bad[1, 0, 0] = np.nan
    with pytest.raises(NonFiniteInputError, match="problems 1"):
        solve_pose_batch(np.stack([P, P]), bad, GRIPPER_CAMERA)


def test_nonsense_pixels_fail_as_a_status_not_an_exception():
    uv = RNG.uniform(0, 1000, (5, 2))
    sol = solve_pose(P, uv, GRIPPER_CAMERA)
    assert sol.status is SolveStatus.FAILED
    assert sol.reason


@pytest.mark.parametrize("value", [-1e308, 1e23, 5e7])
def test_a_coordinate_no_cell_holds_names_its_point(value):
    """A point at -1e308 mm once reached the kernels (ZeroDivisionError); one at 1e23 or 50 km is no cell's."""
    from calib_core.solver import OutOfRangeInputError

    p3 = P.copy()
    p3[2, 0] = value
    with pytest.raises(OutOfRangeInputError, match="point 3") as info:
        solve_pose(p3, UV, GRIPPER_CAMERA)
    assert info.value.points == (2,) and "is the unit right" in str(info.value)
    uv = UV.copy()
    uv[4, 1] = value
    with pytest.raises(OutOfRangeInputError, match="point 5"):
        solve_pose(P, uv, GRIPPER_CAMERA)
