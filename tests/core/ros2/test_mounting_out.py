"""The camera mounting written for ROS 2: the URDF read alone by Pinocchio's URDF parser (the reader robot software
uses), the xacro macro included and called in a robot's description and expanded by xacro, the launch file's
static_transform_publisher arguments read back as tf2 reads them (metres, a
quaternion x y z w); both against the transform written, for random mountings."""

from __future__ import annotations

import ast

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from calib_core.frames import make_transform
from calib_core.ros2.mounting_out import mounting_text_for, static_transform_launch, urdf_document, xacro_macro


def _mountings(n=6, seed=4):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield make_transform(Rotation.random(random_state=rng).as_matrix(), rng.uniform(-300, 300, 3))


def _placed(urdf: str, child: str) -> pin.SE3:
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    pin.forwardKinematics(model, data, np.zeros(model.nq))
    pin.updateFramePlacements(model, data)
    return data.oMf[model.getFrameId(child)]  # in the root link, metres


@pytest.mark.parametrize("k", range(6))
def test_the_urdf_is_read_alone_and_places_the_camera_where_the_mounting_says(k):
    camera2flange = list(_mountings())[k]
    placed = _placed(urdf_document(camera2flange, "tool0"), "videocal_camera_optical_frame")
    np.testing.assert_allclose(placed.rotation, camera2flange[:3, :3], atol=1e-8)
    np.testing.assert_allclose(placed.translation * 1000.0, camera2flange[:3, 3], atol=1e-5)


def test_the_xacro_macro_included_in_a_description_places_the_driver_s_frame(tmp_path):
    """A robot's xacro includes the written macro and calls it with the camera driver's frame; xacro expands it."""
    import xacro

    camera2flange = list(_mountings())[2]
    (tmp_path / "camera_mounting.urdf.xacro").write_text(xacro_macro(camera2flange, "tool0"))
    (tmp_path / "robot.urdf.xacro").write_text(
        '<?xml version="1.0"?><robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="tool0"/><xacro:include filename="camera_mounting.urdf.xacro"/>'
        '<xacro:videocal_camera_mounting child="camera_color_optical_frame"/></robot>'
    )
    urdf = xacro.process_file(str(tmp_path / "robot.urdf.xacro")).toxml()
    placed = _placed(urdf, "camera_color_optical_frame")
    np.testing.assert_allclose(placed.rotation, camera2flange[:3, :3], atol=1e-8)
    np.testing.assert_allclose(placed.translation * 1000.0, camera2flange[:3, 3], atol=1e-5)


def _launch_arguments(text: str) -> dict[str, str]:
    """The Node's ``arguments`` list of the launch file, read from its syntax tree (the file must parse)."""
    tree = ast.parse(text)
    for node in ast.walk(tree):
        if isinstance(node, ast.keyword) and node.arg == "arguments":
            values = [ast.literal_eval(e) for e in node.value.elts]
            return {values[i].lstrip("-"): values[i + 1] for i in range(0, len(values), 2)}
    raise AssertionError("no arguments in the launch file")


@pytest.mark.parametrize("k", range(6))
def test_the_launch_file_publishes_the_mounting_as_tf2_reads_it(k):
    camera2flange = list(_mountings())[k]
    args = _launch_arguments(static_transform_launch(camera2flange, "flange_link"))
    assert args["frame-id"] == "flange_link" and args["child-frame-id"] == "videocal_camera_optical_frame"
    quat = [float(args[key]) for key in ("qx", "qy", "qz", "qw")]
    assert abs(np.linalg.norm(quat) - 1.0) < 1e-8
    np.testing.assert_allclose(Rotation.from_quat(quat).as_matrix(), camera2flange[:3, :3], atol=1e-8)
    np.testing.assert_allclose([float(args[a]) * 1000.0 for a in "xyz"], camera2flange[:3, 3], atol=1e-5)


def test_the_suffix_chooses_the_form_and_a_bad_transform_is_refused():
    T = np.eye(4)
    assert "static_transform_publisher" in mounting_text_for("cam.launch.py", T, "tool0")
    assert "<xacro:macro" in mounting_text_for(
        "cam.urdf.xacro", T, "tool0"
    ) and '<robot name="videocal_camera_mounting">' in mounting_text_for("cam.urdf", T, "tool0")
    assert '"--child-frame-id", "camera_link_optical"' in mounting_text_for(
        "cam.launch.py", T, "tool0", child="camera_link_optical"
    )
    assert mounting_text_for("cam.yaml", T, "tool0") is None
    mirrored = np.diag([1.0, 1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="reflection"):
        urdf_document(mirrored, "tool0")
    with pytest.raises(ValueError, match="finite"):
        static_transform_launch(np.full((4, 4), np.nan), "tool0")
