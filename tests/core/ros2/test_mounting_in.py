"""A camera mounting read from the launch file another tool wrote for ``static_transform_publisher``:
MoveIt 2's hand-eye calibration (a Python launch file, named arguments, quaternion or roll/pitch/yaw), an XML
launch (positional arguments, ROS 1's MoveIt Calibration and hand-written setups), and videocal's own output read
back. The Python file is parsed, never run."""

from __future__ import annotations


import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.errors import FileFormatError, VideocalError
from calib_core.frames import concat, make_transform
from calib_core.robot import load_robot
from calib_core.ros2.mounting_in import read_static_transform
from calib_core.ros2.mounting_out import static_transform_launch
from calib_core.vision.hand_eye_io import load_mounting

# the form MoveIt 2's hand-eye calibration saves (its calibration panel's "save camera pose"), numbers of our own
MOVEIT2_QUATERNION = '''""" Static transform publisher acquired via MoveIt 2 hand-eye calibration """
""" EYE-IN-HAND: tool0 -> camera_color_optical_frame """
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    nodes = [
        Node(
            package="tf2_ros",
            executable="static_transform_publisher",
            output="log",
            arguments=[
                "--frame-id", "tool0",
                "--child-frame-id", "camera_color_optical_frame",
                "--x", "0.0412", "--y", "-0.0803", "--z", "0.0521",
                "--qx", "0.0087", "--qy", "-0.0123", "--qz", "0.7070", "--qw", "0.7071",
                # "--roll", "0.1",
            ],
        ),
    ]
    return LaunchDescription(nodes)
'''


def _quat(q):
    q = np.asarray(q, float)
    return Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()


def test_moveit2_s_launch_file_with_a_quaternion(tmp_path):
    path = tmp_path / "camera.launch.py"
    path.write_text(MOVEIT2_QUATERNION)
    found = read_static_transform(path)
    assert (found.parent, found.child) == ("tool0", "camera_color_optical_frame")
    np.testing.assert_allclose(found.child2parent_mm[:3, 3], [41.2, -80.3, 52.1])
    np.testing.assert_allclose(found.child2parent_mm[:3, :3], _quat([0.0087, -0.0123, 0.7070, 0.7071]), atol=1e-12)


def test_roll_pitch_yaw_are_tf2_s_fixed_axes(tmp_path):
    path = tmp_path / "rpy.launch.py"
    path.write_text(
        MOVEIT2_QUATERNION.replace(
            '"--qx", "0.0087", "--qy", "-0.0123", "--qz", "0.7070", "--qw", "0.7071",',
            '"--roll", "0.3", "--pitch", "-0.2", "--yaw", "1.1",',
        )
    )
    R = read_static_transform(path).child2parent_mm[:3, :3]
    # tf2's setRPY: R = Rz(yaw) Ry(pitch) Rx(roll)
    Rz, Ry, Rx = (
        Rotation.from_rotvec(np.array(a) * v).as_matrix()
        for a, v in (([0, 0, 1], 1.1), ([0, 1, 0], -0.2), ([1, 0, 0], 0.3))
    )
    np.testing.assert_allclose(R, Rz @ Ry @ Rx, atol=1e-12)


def test_an_xml_launch_with_positional_arguments(tmp_path):
    euler = tmp_path / "a.launch"
    euler.write_text(
        '<launch>\n  <node pkg="tf2_ros" type="static_transform_publisher" name="cam" args="0.1 0.02 -0.03 1.1 -0.2 '
        '0.3 flange cam_optical_frame" />\n</launch>\n'
    )
    quat = tmp_path / "b.launch.xml"
    quat.write_text(
        '<launch><node pkg="tf" type="static_transform_publisher" name="cam" args="0.1 0.02 -0.03 0 0 0.7071068 '
        '0.7071068 flange cam_optical_frame 100"/></launch>'
    )
    a, b = read_static_transform(euler), read_static_transform(quat)
    np.testing.assert_allclose(a.child2parent_mm[:3, 3], [100.0, 20.0, -30.0])
    np.testing.assert_allclose(
        a.child2parent_mm[:3, :3], Rotation.from_euler("xyz", [0.3, -0.2, 1.1]).as_matrix(), atol=1e-12
    )  # yaw pitch roll given
    np.testing.assert_allclose(
        b.child2parent_mm[:3, :3], Rotation.from_rotvec([0, 0, np.pi / 2]).as_matrix(), atol=1e-6
    )
    assert (b.parent, b.child) == ("flange", "cam_optical_frame")


def test_videocal_s_own_launch_file_reads_back(tmp_path):
    T = make_transform(Rotation.from_rotvec([0.2, -0.4, 1.3]).as_matrix(), [12.5, -60.25, 88.0])
    path = tmp_path / "mount.launch.py"
    path.write_text(static_transform_launch(T, "tool0"))
    found = read_static_transform(path)
    assert found.parent == "tool0" and "optical" in found.child
    np.testing.assert_allclose(found.child2parent_mm, T, atol=1e-5)


def test_the_python_launch_file_is_never_run(tmp_path):
    marker = tmp_path / "ran"
    path = tmp_path / "evil.launch.py"
    path.write_text(f"import pathlib\npathlib.Path({str(marker)!r}).write_text('x')\n" + MOVEIT2_QUATERNION)
    read_static_transform(path)
    assert not marker.exists()
    computed = tmp_path / "computed.launch.py"
    computed.write_text(MOVEIT2_QUATERNION.replace('"--x", "0.0412"', '"--x", str(0.04 + 0.0012)'))
    with pytest.raises(FileFormatError, match="constants"):
        read_static_transform(computed)


@pytest.mark.parametrize(
    "text, says",
    [
        ("from launch import LaunchDescription\n", "no static_transform_publisher"),
        (MOVEIT2_QUATERNION.replace('"--qw", "0.7071"', '"--qw", "0.9"'), "unit quaternion"),
        (MOVEIT2_QUATERNION.replace('"--x", "0.0412"', '"--x", "abc"'), "x must be a number"),
        (MOVEIT2_QUATERNION.replace('"--frame-id", "tool0",', ""), "--frame-id"),
        (MOVEIT2_QUATERNION.replace('"--x", "0.0412",', '"--x", "0.0412", "--speed", "3",'), "unknown"),
        ("def f(:\n", "not a Python launch file"),
    ],
)
def test_bad_launch_files_are_refused_by_name(tmp_path, text, says):
    path = tmp_path / "bad.launch.py"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=says) as err:
        read_static_transform(path)
    assert str(path) in str(err.value)


def test_a_camera_link_is_not_taken_for_the_optical_frame(tmp_path):
    path = tmp_path / "link.launch.py"
    path.write_text(MOVEIT2_QUATERNION.replace("camera_color_optical_frame", "camera_link"))
    with pytest.raises(FileFormatError, match="not an optical frame"):
        load_mounting(path)


def test_a_mounting_on_another_frame_of_the_flange_s_link_is_moved_onto_the_flange(tmp_path):
    """The bundled robot's flange and tcp ride on one link: a mounting given on the tcp becomes the same camera on
    the flange; one given on a link that a joint moves is refused."""
    robot = load_robot()
    cam2tcp = make_transform(Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix(), [10.0, 20.0, 30.0])
    cam2flange = robot.on_flange(cam2tcp, robot.roles.get("tcp", "tcp"), "test")
    q = np.zeros(robot.n_joints)
    np.testing.assert_allclose(
        concat(cam2flange, robot.fk(q, "flange")), concat(cam2tcp, robot.fk(q, "tcp")), atol=1e-9
    )
    flange_joint = robot.model.frames[robot.frame_id("flange")].parentJoint
    elbow = next(
        f.name for f in robot.model.frames if 0 < f.parentJoint < flange_joint
    )  # a link a joint moves against the flange
    with pytest.raises(VideocalError, match="not fixed to the flange"):
        robot.on_flange(cam2tcp, elbow, "test")
    with pytest.raises(VideocalError, match="not on this cell's robot"):
        robot.on_flange(cam2tcp, "no_such_frame", "test")
