"""camera_info as ROS 2 prints it (`ros2 topic echo`), from a user's RealSense; and ROS 1's upper-case fields."""

from pathlib import Path

import pytest

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.errors import FileFormatError

ECHO = Path(__file__).parents[2] / "data" / "third_party" / "ros_echo" / "realsense_color_camera_info.txt"


def test_a_realsense_camera_info_as_ros2_topic_echo_prints_it():
    i = load_intrinsics(ECHO)
    assert (i.width, i.height) == (640, 480)
    assert (i.fu, i.fv, i.cx, i.cy) == pytest.approx(
        (386.45025634765625, 386.0099792480469, 324.7872314453125, 241.43978881835938)
    )
    assert i.distortion == pytest.approx(
        (
            -0.05422300472855568,
            0.062016744166612625,
            0.00011767349496949464,
            0.0008119725971482694,
            -0.01983201690018177,
        )
    )


def test_ros1_upper_case_fields_and_a_wrong_one(tmp_path):
    ros1 = tmp_path / "info.yaml"
    ros1.write_text(
        "height: 480\nwidth: 640\ndistortion_model: plumb_bob\nD: [0.1, -0.2, 0.0, 0.0, 0.0]\n"
        "K: [500.0, 0.0, 320.0, 0.0, 501.0, 240.0, 0.0, 0.0, 1.0]\nR: [1, 0, 0, 0, 1, 0, 0, 0, 1]\nP: [500, 0, 320, 0, "
        "0, 501, 240, 0, 0, 0, 1, 0]\n"
    )
    assert load_intrinsics(ros1).fv == 501.0
    bad = tmp_path / "bad.yaml"
    bad.write_text("height: 480\nwidth: 640\nk: [500.0, 0.0, 320.0]\n")
    with pytest.raises(FileFormatError, match="field 'k'.*must be a list of 9 numbers|k.*9 numbers"):
        load_intrinsics(bad)
