"""Vendor descriptions as shipped: ROS-Industrial's KUKA KR 6 R900 sixx xacro (``$(find kuka_resources)``,
``package://`` meshes) without ROS, packages found through --package-path, ROS_PACKAGE_PATH or AMENT_PREFIX_PATH;
xacro arguments; runaway expressions bounded in time and memory."""

import math
import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.robot.description import read_description
from calib_core.robot.model import load_robot
from calib_core.robot.spec import RobotSpec
from calib_core.robot.xacro_expand import expand_xacro

KUKA = Path(__file__).parents[2] / "data" / "third_party" / "ros_industrial" / "kuka_experimental"
KR6 = KUKA / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro"


@pytest.fixture(autouse=True)
def no_ros_environment(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def test_without_a_package_path_the_error_says_which_package_and_where_to_say_it():
    with pytest.raises(FileFormatError) as info:
        read_description(KR6)
    text = str(info.value)
    assert "kr6r900sixx.xacro" in text and "$(find kuka_kr6_support)" in text and "--package-path" in text


def _origins_to_tool0(urdf_text: str) -> np.ndarray:
    """tool0 in base_link at zero joints, by chaining the joints' <origin>s of the expanded URDF (an answer of
    its own, beside Pinocchio's)."""
    root = ET.fromstring(urdf_text)
    by_child = {j.find("child").get("link"): j for j in root.iter("joint")}
    chain, link = [], "tool0"
    while link in by_child:
        joint = by_child[link]
        chain.append(joint)
        link = joint.find("parent").get("link")
    assert link == "base_link"
    T = np.eye(4)
    for joint in reversed(chain):
        origin = joint.find("origin")
        xyz = [float(v) for v in (origin.get("xyz") if origin is not None else "0 0 0").split()]
        r, p, y = [
            float(v) for v in (origin.get("rpy") if origin is not None and origin.get("rpy") else "0 0 0").split()
        ]
        cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
        R = np.array(
            [
                [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                [-sp, cp * sr, cp * cr],
            ]
        )
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = R, xyz
        T = T @ step
    return T


@pytest.mark.parametrize("how", ["package path", "ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"])
def test_the_kr6_loads_as_shipped(how, monkeypatch, tmp_path):
    paths = ()
    if how == "package path":
        paths = (KUKA,)  # the repository checkout: packages found by their package.xml
    elif how == "ROS_PACKAGE_PATH":
        monkeypatch.setenv("ROS_PACKAGE_PATH", str(KUKA))
    else:  # an installed ROS 2 workspace: <prefix>/share/<package>
        share = tmp_path / "install" / "share"
        share.mkdir(parents=True)
        for package in ("kuka_kr6_support", "kuka_resources"):
            (share / package).symlink_to(KUKA / package)
        monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "install"))
    urdf = read_description(KR6, paths)
    robot = load_robot(RobotSpec(KR6, paths, {"base": None, "flange": "tool0", "tcp": "tool0", "camera": "tool0"}))
    assert robot.joint_names == [f"joint_a{i}" for i in range(1, 7)]
    tool0 = robot.fk(np.zeros(6), "tool0")
    assert np.allclose(tool0[:3, 3], _origins_to_tool0(urdf)[:3, 3] * 1000.0, atol=1e-6)
    # By hand from the macro's joint origins: at zero the arm points along x (25 + 455 + 420 + 80 mm), 400 + 35 mm up
    assert tool0[0, 3] == pytest.approx(980.0, abs=1e-6) and tool0[2, 3] == pytest.approx(435.0, abs=1e-6)
    mesh_paths = [m.get("filename") for m in ET.fromstring(urdf).iter("mesh")]
    assert mesh_paths and all(Path(p).is_file() for p in mesh_paths)


def test_xacro_arguments(tmp_path):
    source = tmp_path / "arm.urdf.xacro"
    source.write_text("""<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="prefix" default=""/>
  <xacro:arg name="reach" default="0.5"/>
  <link name="$(arg prefix)base"/>
  <link name="$(arg prefix)tip"/>
  <joint name="$(arg prefix)j1" type="revolute">
    <parent link="$(arg prefix)base"/><child link="$(arg prefix)tip"/>
    <origin xyz="$(arg reach) 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>""")
    urdf = read_description(source, (), {"prefix": "left_", "reach": "0.75"})
    assert 'name="left_j1"' in urdf and 'xyz="0.75 0 0"' in urdf
    assert 'name="j1"' in read_description(source)  # the defaults


def test_runaway_expressions_are_bounded(tmp_path):
    slow = tmp_path / "slow.xacro"
    slow.write_text(
        '<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="x" '
        'value="${9**9**9}"/><link name="${x}"/></robot>'
    )
    with pytest.raises(FileFormatError, match="slow.xacro.*took longer than 2 s"):
        expand_xacro(slow, [], timeout_s=2)
    big = tmp_path / "big.xacro"
    big.write_text(
        """<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">
<xacro:property name="x" value="${'a'*10**10}"/><link name="${x}"/></robot>"""
    )
    with pytest.raises(FileFormatError, match="big.xacro.*needed more than 512 MB"):
        expand_xacro(big, [], memory_mb=512)


def test_a_calibrated_kr6_keeps_its_package_meshes_and_its_corrected_joint(tmp_path):
    """The calibrated URDF as robot_calibration writes it: the vendor's ``package://`` mesh names, not this machine's
    paths; read back (with the package path) it has the corrected joint origin and the same meshes."""
    from calib_core.robot_calibration.report import calibrated_urdf

    spec = RobotSpec(KR6, (KUKA,), {"base": None, "flange": "tool0", "tcp": "tool0", "camera": "tool0"})
    nominal = load_robot(spec)
    calibrated = nominal.copy()
    k = calibrated.model.getJointId("joint_a2")
    calibrated.model.jointPlacements[k].translation = calibrated.model.jointPlacements[k].translation + np.array(
        [0.0004, -0.0002, 0.0003]
    )
    text, left = calibrated_urdf(nominal, calibrated, camera_frame="tool0")
    meshes = [m.get("filename") for m in ET.fromstring(text).iter("mesh")]
    assert meshes and all(m.startswith("package://kuka_kr6_support/meshes/") for m in meshes), meshes[:3]
    out = tmp_path / "kr6_calibrated.urdf"
    out.write_text(text)
    again = load_robot(RobotSpec(out, (KUKA,), {"base": None, "flange": "tool0", "tcp": "tool0", "camera": "tool0"}))
    q = np.array([10.0, -20.0, 30.0, 5.0, 40.0, -15.0])  # deg
    np.testing.assert_allclose(again.fk(q, "tool0"), calibrated.fk(q, "tool0"), atol=1e-6)
    assert not np.allclose(again.fk(q, "tool0"), nominal.fk(q, "tool0"), atol=1e-3)


def test_the_xacro_child_ends_with_its_parent(tmp_path):
    """A runaway expansion went on computing after the command that started it was killed."""
    import signal
    import subprocess
    import sys
    import time

    slow = tmp_path / "slow.xacro"
    slow.write_text(
        '<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="x" '
        'value="${9**9**9}"/><link name="${x}"/></robot>'
    )
    parent = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; from pathlib import Path; from calib_core.robot.xacro_expand import expand_xacro; "
            "print('expanding', flush=True); expand_xacro(Path(sys.argv[1]), [], timeout_s=120)",
            str(slow),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert parent.stdout.readline().strip() == "expanding"

    def children() -> list[str]:
        found = subprocess.run(
            ["pgrep", "-P", str(parent.pid), "-f", "xacro_child"], capture_output=True, text=True
        ).stdout.split()
        return found

    deadline = time.monotonic() + 20
    while not children() and time.monotonic() < deadline:
        time.sleep(0.05)
    child = children()
    assert child, "the child never started"
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait(5)
    parent.stdout.close()
    deadline = time.monotonic() + 10
    while os.path.exists(f"/proc/{child[0]}") and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not os.path.exists(f"/proc/{child[0]}") or open(f"/proc/{child[0]}/stat").read().split()[2] == "Z"
