"""OpenCV's rational (8-coefficient) and fisheye (equidistant) lenses beside its 5-coefficient one: projection
against OpenCV's own ``projectPoints`` and ``fisheye.projectPoints``, back-projection as its inverse, the files ROS and
OpenCV write, and a pose solved through each lens."""

import cv2
import numpy as np
import pytest
import yaml

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics, save_intrinsics
from calib_core.camera.projection import as_pinhole, project, project_points, unproject
from calib_core.errors import FileFormatError
from calib_core.frames import transform_from_xyz_rpy
from calib_core.solver import solve_pose

RATIONAL = Intrinsics(
    1120.0, 1116.0, 645.2, 476.8, 1280, 960, (-0.2, 0.05, 6e-4, -4e-4, -0.01, 0.12, -0.03, 0.01), "rational_polynomial"
)
FISHEYE = Intrinsics(620.0, 618.0, 641.0, 479.0, 1280, 960, (-0.012, 0.004, -0.0015, 0.0002), "equidistant")
RNG = np.random.default_rng(5)


def _points(n: int = 60, spread: float = 1.2) -> np.ndarray:
    """Points in the camera frame (mm) filling a wide field of view, 300-900 mm away."""
    z = RNG.uniform(300, 900, n)
    return np.column_stack([RNG.uniform(-spread, spread, n) * z, RNG.uniform(-spread * 0.75, spread * 0.75, n) * z, z])


def test_rational_projection_is_opencvs():
    p = _points()
    ours = project(p, RATIONAL)
    theirs = cv2.projectPoints(p, np.zeros(3), np.zeros(3), RATIONAL.K, RATIONAL.dist_coeffs)[0].reshape(-1, 2)
    assert np.allclose(ours, theirs, atol=1e-6)


def test_fisheye_projection_is_opencvs():
    p = _points()
    ours = project(p, FISHEYE)
    theirs = cv2.fisheye.projectPoints(
        p.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), FISHEYE.K, FISHEYE.dist_coeffs.reshape(4, 1)
    )[0].reshape(-1, 2)
    assert np.allclose(ours, theirs, atol=1e-6)
    # a fisheye sees wider than a pinhole could: 50 deg off axis lands inside the image
    assert FISHEYE.contains(project(np.array([[np.tan(np.radians(50)) * 500, 0.0, 500.0]]), FISHEYE))[0]


@pytest.mark.parametrize("lens", [RATIONAL, FISHEYE], ids=["rational", "fisheye"])
def test_back_projection_inverts_projection(lens):
    p = _points()
    px = project(p, lens)
    keep = lens.contains(px)
    back = unproject(px[keep], lens, depth_mm=p[keep, 2])
    assert np.allclose(back, p[keep], atol=1e-6)
    ideal, pinhole = as_pinhole(px[keep], lens)
    assert pinhole.model == "plumb_bob" and not pinhole.has_distortion
    assert np.allclose(ideal, project(p[keep], pinhole), atol=1e-6)  # the ideal pinhole sees the same rays


@pytest.mark.parametrize("lens", [RATIONAL, FISHEYE], ids=["rational", "fisheye"])
def test_a_pose_is_solved_through_the_lens(lens):
    obj2cam = transform_from_xyz_rpy([40.0, -25.0, 520.0], [168.0, 12.0, -35.0])
    points = np.column_stack([RNG.uniform(-250, 250, 12), RNG.uniform(-180, 180, 12), RNG.uniform(-40, 40, 12)])
    pixels = project_points(points, obj2cam, lens)
    assert lens.contains(pixels).all()
    solution = solve_pose(points, pixels + RNG.normal(0.0, 0.05, pixels.shape), lens)
    assert solution.status.value == "ok"
    assert np.linalg.norm(solution.obj2cam[:3, 3] - obj2cam[:3, 3]) < 0.5
    # the same pixels read as an undistorted camera give a pose that is off: the lens mattered
    wrong = solve_pose(points, pixels, lens.without_distortion())
    assert np.linalg.norm(wrong.obj2cam[:3, 3] - obj2cam[:3, 3]) > 2.0


def test_camera_info_of_each_model_is_read_as_ros_writes_it(tmp_path):
    # camera_calibration's ost.yaml for a fisheye lens
    ost = {
        "image_width": 1280,
        "image_height": 960,
        "camera_name": "wide",
        "camera_matrix": {"rows": 3, "cols": 3, "data": FISHEYE.K.ravel().tolist()},
        "distortion_model": "equidistant",
        "distortion_coefficients": {"rows": 1, "cols": 4, "data": list(FISHEYE.distortion)},
        "rectification_matrix": {"rows": 3, "cols": 3, "data": np.eye(3).ravel().tolist()},
        "projection_matrix": {"rows": 3, "cols": 4, "data": np.c_[FISHEYE.K, np.zeros(3)].ravel().tolist()},
    }
    (tmp_path / "ost.yaml").write_text(yaml.safe_dump(ost))
    assert load_intrinsics(tmp_path / "ost.yaml") == FISHEYE
    # `ros2 topic echo --once /camera/camera_info` of a rational lens
    echo = "\n".join(
        [
            "header:",
            "  stamp:",
            "    sec: 0",
            "    nanosec: 0",
            "  frame_id: camera",
            "height: 960",
            "width: 1280",
            "distortion_model: rational_polynomial",
            "d:",
        ]
        + [f"- {v}" for v in RATIONAL.distortion]
        + ["k:"]
        + [f"- {v}" for v in RATIONAL.K.ravel()]
        + ["---"]
    )
    (tmp_path / "echo.yaml").write_text(echo + "\n")
    assert load_intrinsics(tmp_path / "echo.yaml") == RATIONAL
    # a fisheye model with a plumb_bob's five coefficients is named, not guessed at
    ost["distortion_coefficients"] = {"rows": 1, "cols": 5, "data": [0.1, 0.01, 0.0, 0.0, 0.0]}
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(ost))
    with pytest.raises(FileFormatError, match="bad.yaml.*equidistant lens has 4 coefficients.*gives 5"):
        load_intrinsics(tmp_path / "bad.yaml")
    ost["distortion_model"] = "kannala_brandt_8"
    (tmp_path / "unknown.yaml").write_text(yaml.safe_dump(ost))
    with pytest.raises(FileFormatError, match="unsupported distortion model 'kannala_brandt_8'"):
        load_intrinsics(tmp_path / "unknown.yaml")
    # a list where the model's name belongs (a fuzzed document: it raised TypeError "unhashable type")
    ost["distortion_model"] = ["plumb_bob"]
    (tmp_path / "listed.yaml").write_text(yaml.safe_dump(ost))
    with pytest.raises(FileFormatError, match="listed.yaml.*unsupported distortion model \\['plumb_bob'\\]"):
        load_intrinsics(tmp_path / "listed.yaml")


@pytest.mark.parametrize("fmt", ["opencv", "ros"])
@pytest.mark.parametrize("lens", [RATIONAL, FISHEYE], ids=["rational", "fisheye"])
def test_written_files_read_back(tmp_path, fmt, lens):
    save_intrinsics(tmp_path / "camera.yaml", lens, fmt=fmt)
    assert load_intrinsics(tmp_path / "camera.yaml") == lens
    assert Intrinsics.from_dict(lens.to_dict()) == lens
