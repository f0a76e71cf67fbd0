"""One name for the camera's frame in everything ROS is given, chosen in the workcell's site section."""

import shutil

import pytest

from calib_core.errors import FileFormatError
from calib_core.ros2.frame_names import DEFAULT_CAMERA_FRAME, camera_frames
from calib_core.workcell import DEFAULT_WORKCELL, load_workcell


def _cell_with_site(tmp_path, site_text: str):
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):  # a copy: the file's relative paths hold
        shutil.copytree(root / sub, tmp_path / sub)
    path = tmp_path / "workcell" / "workcell.yaml"
    path.write_text(path.read_text() + "\nsite:\n" + site_text)
    return load_workcell(path)


def test_the_site_names_the_camera_driver_s_frame_and_its_parent(tmp_path):
    cell = _cell_with_site(tmp_path, "  camera_frame: camera_color_optical_frame\n  camera_parent_frame: tool0\n")
    assert camera_frames(cell) == ("tool0", "camera_color_optical_frame")


def test_without_a_site_the_defaults_are_the_flange_and_videocal_s_optical_frame():
    cell = load_workcell(DEFAULT_WORKCELL)
    parent, child = camera_frames(cell, flange_frame="flange")
    assert child == DEFAULT_CAMERA_FRAME == "videocal_camera_optical_frame"
    assert parent == str(cell.robot_spec.frames.get("flange") or "flange")
    assert (
        camera_frames(None) == ("tool0", DEFAULT_CAMERA_FRAME)
        and camera_frames(None, static_camera=True)[0] == "base_link"
    )


@pytest.mark.parametrize("bad", ["'9camera'", "'camera frame'", "'cam\\nera'", "[a]"])
def test_a_frame_name_tf_cannot_take_is_refused_with_its_field(tmp_path, bad):
    with pytest.raises(FileFormatError) as info:
        _cell_with_site(tmp_path, f"  camera_frame: {bad}\n")
    assert info.value.field == "site.camera_frame" and "tf frame name" in str(info.value)
