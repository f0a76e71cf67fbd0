"""new-cell places the task where the arm stands unfolded, and the TCP on the flange by one convention.

KUKA's KR 6 package as shipped reached the old task folded (A2 -143 deg, A3 +144 deg: the upper arm leaning back over
the base); FANUC's LR Mate 200iD and Yaskawa's GP7 likewise. The TCP's frame on ``tool0`` was turned by whatever the
vendor's ``tool0`` is turned (GP7 90 deg, FANUC 0): now it is ``tool0`` moved along its z, for every vendor, and a
flange turned about the tool moves neither the camera nor the task in the cell.
"""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.workcell import load_workcell
from calib_core.workcell.starter import TCP_MM, write_starter_cell
from calib_core.workcell.task_pose import ArmJoints, posture

KUKA = Path(__file__).parents[2] / "data" / "third_party" / "ros_industrial" / "kuka_experimental"
FORWARD = np.array([1.0, 0.0, 0.0])


def _kr6(tmp_path, tool0_roll_deg: float = 0.0) -> Path:
    package = tmp_path / f"kuka_{tool0_roll_deg:.0f}"
    shutil.copytree(KUKA, package)
    if tool0_roll_deg == 0.0:
        return package
    macro = package / "kuka_kr6_support" / "urdf" / "kr6r900sixx_macro.xacro"
    # the shipped tool0 (pitch 90 deg on the flange), then turned about its own z
    rpy = Rotation.from_euler("YZ", [90.0, tool0_roll_deg], degrees=True).as_euler("xyz")
    text, n = re.subn(
        r'(<child link="\$\{prefix\}tool0"/>\s*<origin xyz="0 0 0" rpy=")0 \$\{radians\(90\)\} 0(")',
        rf"\g<1>{' '.join(repr(float(v)) for v in rpy)}\g<2>",
        macro.read_text(),
    )
    assert n == 1
    macro.write_text(text)
    return package


@pytest.fixture(scope="module")
def kr6_cell(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("kr6")
    package = _kr6(tmp)
    made = write_starter_cell(tmp / "cell", package / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", [package])
    return made, load_workcell(made.workcell_path)


def test_the_posture_tells_a_folded_arm_from_an_unfolded_one(kr6_cell):
    made, cell = kr6_cell
    robot = cell.load_robot()
    joints = ArmJoints.of(robot)
    # the pose the old placement chose: the upper arm leaning back over the base
    folded = posture(robot, joints, [0.0, -143.2, 143.8, 0.0, -0.6, 0.0], FORWARD)
    assert folded.lean_back and not folded.unfolded
    # KUKA's own home (A2 -90, A3 +90: upper arm up, forearm forward): the elbow at a right angle, up
    home = posture(robot, joints, [0.0, -90.0, 90.0, 0.0, 0.0, 0.0], FORWARD)
    assert home.unfolded and home.elbow_up and abs(home.elbow_deg - 90.0) < 5.0
    # the same joints with the elbow bent the other way: below the shoulder-wrist line
    assert not posture(robot, joints, [0.0, -20.0, -60.0, 0.0, 0.0, 0.0], FORWARD).elbow_up


def test_the_new_cell_reaches_its_task_unfolded_with_the_wrist_not_turned_over(kr6_cell):
    made, cell = kr6_cell
    robot = cell.load_robot()
    joints = ArmJoints.of(robot)
    at_home = posture(robot, joints, made.home_joints, FORWARD)
    assert at_home.unfolded, at_home
    assert abs(made.home_joints[3]) < 90.0 and abs(made.home_joints[5]) < 90.0  # A4/A6 not at 180
    from calib_core.robot import solve_ik

    grasp = solve_ik(robot, made.task_tcp2base, made.home_joints, extra_seeds=0).q_deg
    assert posture(robot, joints, grasp, FORWARD).unfolded
    # the task in front: the tool along base +x, the target beyond it
    assert made.task_tcp2base[:3, 2] @ FORWARD > 0.999 and made.target2base[0, 3] > made.task_tcp2base[0, 3]


def test_the_tcp_is_the_flange_moved_along_its_z_whatever_way_the_vendor_turns_tool0(tmp_path, kr6_cell):
    made, cell = kr6_cell
    turned_pkg = _kr6(tmp_path, tool0_roll_deg=90.0)
    turned = write_starter_cell(
        tmp_path / "turned", turned_pkg / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", [turned_pkg]
    )
    turned_cell = load_workcell(turned.workcell_path)
    for c in (cell, turned_cell):
        robot = c.load_robot()
        tcp2flange = np.linalg.solve(robot.fk(np.zeros(6), "flange"), robot.fk(np.zeros(6), "tcp"))
        np.testing.assert_allclose(tcp2flange[:3, :3], np.eye(3), atol=1e-9)
        np.testing.assert_allclose(tcp2flange[:3, 3], [0.0, 0.0, TCP_MM], atol=1e-6)
    # the vendor's turn of tool0 moves neither the camera in the cell nor the task: the same view of the target
    views = []
    for m, c in ((made, cell), (turned, turned_cell)):
        robot = c.load_robot()
        views.append(robot.fk(m.home_joints, "camera"))
    np.testing.assert_allclose(views[0][:3, 3], views[1][:3, 3], atol=0.5)
    np.testing.assert_allclose(views[0][:3, :3], views[1][:3, :3], atol=1e-3)
    np.testing.assert_allclose(made.target2base, turned.target2base, atol=1e-6)
