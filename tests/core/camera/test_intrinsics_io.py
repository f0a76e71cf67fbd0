from pathlib import Path

import pytest

from calib_core.camera import Intrinsics
from calib_core.camera.intrinsics_io import load_intrinsics, save_intrinsics
from calib_core.errors import FileFormatError

INTR = Intrinsics(1100.5, 1098.25, 641.3, 478.9, 1280, 960, (-0.12, 0.05, 0.0005, -0.0003, 0.001))


@pytest.mark.parametrize("fmt", ["opencv", "ros"])
def test_round_trip(tmp_path, fmt):
    path = tmp_path / f"cam_{fmt}.yaml"
    save_intrinsics(path, INTR, fmt=fmt)
    assert load_intrinsics(path) == INTR
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "temporary file left behind"


def test_reads_opencv_file_written_by_hand(tmp_path):
    path = tmp_path / "calib.yml"
    path.write_text(
        "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
        "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 319.5, 0., 510., 239.5, 0., 0., 1. ]\n"
        "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 4\n   dt: d\n"
        "   data: [ -0.1, 0.01, 0., 0. ]\n"
    )
    intr = load_intrinsics(path)
    assert (intr.fu, intr.fv, intr.cx, intr.cy, intr.width, intr.height) == (500, 510, 319.5, 239.5, 640, 480)
    assert intr.distortion == (-0.1, 0.01, 0.0, 0.0, 0.0)


def test_reads_ros_file_written_by_hand(tmp_path):
    path = tmp_path / "camera_info.yaml"
    path.write_text(
        "image_width: 1280\nimage_height: 960\ncamera_name: gripper\n"
        "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [1100, 0, 639.5, 0, 1100, 479.5, 0, 0, 1]\n"
        "distortion_model: plumb_bob\n"
        "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0.1, 0, 0, 0, 0]\n"
    )
    intr = load_intrinsics(path)
    assert intr.fu == 1100 and intr.cy == 479.5 and intr.distortion[0] == 0.1


def test_save_failure_keeps_old_file(tmp_path):
    path = tmp_path / "cam.yaml"
    save_intrinsics(path, INTR, fmt="ros")
    before = path.read_bytes()
    with pytest.raises(ValueError):
        save_intrinsics(path, INTR, fmt="matlab")
    assert path.read_bytes() == before


BAD_FILES = {
    "missing.yaml": (None, "no such intrinsics file"),
    "garbage.yaml": ("camera_matrix: [1, 2\n  : ]]\n", "not valid YAML"),
    "foreign.yaml": ("name: robot\njoints: 6\n", "not an intrinsics file"),
    "ros_short.yaml": (
        "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0]\n",
        "field 'camera_matrix.data': expected 9 numbers",
    ),
    "ros_text.yaml": (
        "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [a, 0, 0, 0, 1, 0, 0, 0, "
        "1]\n",
        "field 'camera_matrix.data': data must be a list of numbers",
    ),
    "ros_width.yaml": (
        "image_width: 64.5\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, 320, 0, 500, "
        "240, 0, 0, 1]\n",
        "field 'image_width'",
    ),
    "ros_unknown.yaml": (
        "image_width: 640\nimage_height: 480\nlens: fisheye\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [500, 0, "
        "320, 0, 500, 240, 0, 0, 1]\n",
        "unknown key.*lens",
    ),
    "ros_negative_focal.yaml": (
        "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [-500, 0, 320, 0, 500, "
        "240, 0, 0, 1]\n",
        "focal lengths must be positive",
    ),
    "cv_no_height.yaml": (
        "%YAML:1.0\n---\nimage_width: 640\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 319.5, 0., 510., 239.5, 0., 0., 1. ]\n",
        "field 'image_height': missing",
    ),
    "cv_2x2.yaml": (
        "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n   rows: 2\n   cols: 2\n "
        "  dt: d\n"
        "   data: [ 500., 0., 0., 510. ]\n",
        "field 'camera_matrix': expected a 3x3 matrix",
    ),
    "plain_ragged.json": (
        '{"K": [[500, 0, 320], [0, 500]], "dist": [0, 0, 0, 0], "image_size": [640, 480]}',
        "field 'K': must be a list of numbers",
    ),
    "plain_eight.json": ('{"K": [500, 0, 320, 0, 500, 240, 0, 0], "image_size": [640, 480]}', "field 'K': .*got 8"),
    "plain_text.json": (
        '{"K": [[500, 0, 320], [0, 500, 240], [0, 0, 1]], "dist": ["a", 0, 0, 0], "image_size": [640, 480]}',
        "field 'dist': must be a list of numbers",
    ),
    "plain_size.json": ('{"K": [[500, 0, 320], [0, 500, 240], [0, 0, 1]], "image_size": 640}', "field 'image_size'"),
    "plain_no_size.json": ('{"mtx": [[500, 0, 320], [0, 500, 240], [0, 0, 1]]}', "field 'image_size': missing"),
    "plain_nan.yaml": (
        "K: [[.nan, 0, 320], [0, 500, 240], [0, 0, 1]]\nimage_size: [640, 480]\n",
        "field 'K': contains NaN",
    ),
    "cv_broken.yaml": (
        "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: [\n",
        "cannot parse|cannot open|camera_matrix",
    ),
}


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_files_name_file_and_field(tmp_path, name):
    content, message = BAD_FILES[name]
    path = tmp_path / name
    if content is not None:
        path.write_text(content)
    with pytest.raises(FileFormatError, match=message) as info:
        load_intrinsics(path)
    assert str(path) in str(info.value)
    assert isinstance(info.value, ValueError)


def test_directory_is_not_a_file(tmp_path):
    with pytest.raises(FileFormatError, match="not a regular file"):
        load_intrinsics(Path(tmp_path))


def test_reads_the_plain_matrices_a_script_dumps_as_json(tmp_path):
    """A real set's intrinsics.json (a RealSense's, as its recording script wrote it: K as rows, five coefficients
    nested, the size as a pair): the same camera as the OpenCV file of the same numbers."""
    path = tmp_path / "intrinsics.json"
    path.write_text(
        '{"K": [[634.578, 0.0, 641.951], [0.0, 634.056, 358.995], [0.0, 0.0, 1.0]],\n'
        ' "dist": [[-0.0606, 0.0713, -0.0002, 0.0007, -0.0231]], "image_size": [1280, 720], "rms": 0.21}\n'
    )
    intr = load_intrinsics(path)
    assert (intr.fu, intr.fv, intr.cx, intr.cy, intr.width, intr.height) == (
        634.578,
        634.056,
        641.951,
        358.995,
        1280,
        720,
    )
    assert intr.distortion == (-0.0606, 0.0713, -0.0002, 0.0007, -0.0231) and intr.model == "plumb_bob"
    save_intrinsics(tmp_path / "same.yaml", intr, fmt="opencv")
    assert load_intrinsics(tmp_path / "same.yaml") == intr
    # as YAML, flat, the size from the images and no distortion
    flat = tmp_path / "camera.yaml"
    flat.write_text("camera_matrix: [500, 0, 320, 0, 510, 240, 0, 0, 1]\n")
    intr = load_intrinsics(flat, image_size=(640, 480))
    assert (intr.fu, intr.fv, intr.width, intr.height) == (500, 510, 640, 480) and not any(intr.distortion)
