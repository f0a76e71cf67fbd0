"""The arm's configuration at a target, on vendor robots as ROS-Industrial ships them: KUKA's KR 6 R900 sixx
(``kuka_experimental``) and ABB's IRB 1200-5/0.9 (``abb_experimental``). Checked two ways: the vendors' definitions
applied by hand to the arm's data-sheet dimensions (the wrist centre's x in the axis-1 frame, its side of the lower
arm), and poses whose answer the definition gives outright. Then through a listing: the S/T and confdata printed
for a corrected target are those of the arm at it."""

import math
import re
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.frames import transform_from_xyz_rpy
from calib_core.connectors.joint_map import JointMap
from calib_core.robot.description import package_search_roots
from calib_core.robot.model import load_robot
from calib_core.robot.spec import RobotSpec
from calib_core.robot.xacro_expand import expand_xacro
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.arm_configuration import (
    NotASixAxisArmError,
    abb_confdata,
    arm_configuration,
    kuka_status_turn,
)
from calib_core.workspace.controller_formats import REFERENCE_POSES, controller_listing
from tests.vendor_robots import SHARE, UR5, require

ROS_I = Path(__file__).parents[2] / "data" / "third_party" / "ros_industrial"
FRAMES = {"base": None, "flange": "tool0", "tcp": "tool0", "camera": "tool0"}
KUKA_HOME = REFERENCE_POSES["krl"]
ABB_ZERO = REFERENCE_POSES["rapid"]


@pytest.fixture(scope="module")
def kr6():
    kuka = ROS_I / "kuka_experimental"
    return load_robot(RobotSpec(kuka / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", (kuka,), FRAMES))


@pytest.fixture(scope="module")
def irb1200():
    """The IRB 1200 xacro expanded as shipped; its meshes (7 MB, not kept here) left out: the kinematics are the
    joints'."""
    abb = ROS_I / "abb"
    root = ET.fromstring(
        expand_xacro(abb / "abb_irb1200_support" / "urdf" / "irb1200_5_90.xacro", package_search_roots([abb]))
    )
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    path = Path(tempfile.mkdtemp()) / "irb1200_5_90.urdf"
    path.write_text(ET.tostring(root, encoding="unicode"))
    return load_robot(RobotSpec(path, (), FRAMES))


def _kuka(robot, q):
    return arm_configuration(robot, JointMap.identity(6), q, KUKA_HOME)


def _abb(robot, q):
    return arm_configuration(robot, JointMap.identity(6), q, ABB_ZERO)


@pytest.mark.parametrize(
    "q, status, turn",
    [
        ((0, -90, 90, 0, 45, 0), 2, 2),  # home, the wrist bent down: basic area, normal elbow, A5 positive; A2 negative
        ((0, -90, 90, 0, -45, 0), 6, 18),  # the wrist bent the other way: bit 2, and A5's turn bit
        (
            (0, -150, 60, 0, 45, 0),
            3,
            2,
        ),  # the lower arm leant back past the upright: the wrist centre behind axis 1 (overhead)
        ((0, -30, -60, 0, 45, 0), 0, 6),  # the forearm folded past the stretched arm: elbow bit clear
        ((-20, -90, 90, -10, 45, -200), 2, 43),  # turns: A1, A2, A4 and A6 negative
    ],
)
def test_kuka_status_and_turn_at_poses_the_definition_decides(kr6, q, status, turn):
    assert kuka_status_turn(_kuka(kr6, q)) == (status, turn)


def test_kuka_by_the_data_sheet(kr6):
    """KR 6 R900 sixx: A2 25 mm before and 400 mm above A1, lower arm 455 mm, forearm 420 mm with a 35 mm offset. The
    wrist centre's x in the A1 frame and its side of the lower arm, by hand; Status bits 0 and 1 from them
    (bit 1: A3 at or past atan(35/420), where the wrist centre crosses the line of A2 and A3)."""
    rng = np.random.default_rng(7)
    phi = math.degrees(math.atan2(35.0, 420.0))
    for _ in range(40):
        q = np.r_[
            rng.uniform(-170, 170),
            rng.uniform(-190, 45),
            rng.uniform(-119, 155),
            rng.uniform(-185, 185),
            rng.uniform(-119, 119),
            rng.uniform(-350, 350),
        ]
        a2, a3 = np.radians(q[1]), np.radians(q[2])
        x = 25.0 + 455.0 * math.cos(a2) + 420.0 * math.cos(a2 + a3) + 35.0 * math.sin(a2 + a3)
        side = 420.0 * math.sin(a3) - 35.0 * math.cos(a3)
        c = _kuka(kr6, q)
        assert c.wrist_x_mm == pytest.approx(x, abs=1e-6) and c.elbow_mm == pytest.approx(side, abs=1e-6)
        status, _ = kuka_status_turn(c)
        assert status & 1 == (x < 0) and (status >> 1) & 1 == (q[2] >= phi)


@pytest.mark.parametrize(
    "q, confdata",
    [
        ((0, 0, 0, 0, 30, 0), (0, 0, 0, 0)),  # the calibration pose, the wrist bent down
        ((0, 0, 0, 0, -30, 0), (0, 0, 0, 1)),  # axis 5 negative
        ((100, 0, 0, 200, 30, -10), (1, 2, -1, 0)),  # quadrants: 90..180, 180..270, -90..0
        ((0, -90, 0, 0, 30, 0), (0, 0, 0, 4)),  # the lower arm laid back: the wrist centre 490 mm behind axis 1
        ((0, 0, -150, 0, 30, 0), (0, 0, 0, 6)),  # the forearm folded back over: behind axis 1 and behind the lower arm
    ],
)
def test_abb_confdata_at_poses_the_definition_decides(irb1200, q, confdata):
    assert abb_confdata(_abb(irb1200, q)) == confdata


def test_abb_by_the_data_sheet(irb1200):
    """IRB 1200-5/0.9: lower arm 448 mm, forearm 451 mm to the wrist centre with a 42 mm offset; axis 2 tilts the arm
    forward. The wrist centre's x (in front of axis 1) and its side of the lower arm, by hand; cfx from them."""
    rng = np.random.default_rng(11)
    for _ in range(40):
        q = np.r_[
            rng.uniform(-170, 170),
            rng.uniform(-100, 130),
            rng.uniform(-200, 70),
            rng.uniform(-270, 270),
            rng.uniform(-130, 130),
            rng.uniform(-360, 360),
        ]
        a2, a3 = np.radians(q[1]), np.radians(q[2])
        x = 448.0 * math.sin(a2) + 451.0 * math.cos(a2 + a3) + 42.0 * math.sin(a2 + a3)
        side = 451.0 * math.cos(a3) + 42.0 * math.sin(a3)
        c = _abb(irb1200, q)
        assert c.wrist_x_mm == pytest.approx(x, abs=1e-6) and c.elbow_mm == pytest.approx(side, abs=1e-6)
        cf1, cf4, cf6, cfx = abb_confdata(c)
        assert (cf1, cf4, cf6) == tuple(math.floor(v / 90.0) for v in q[[0, 3, 5]])
        assert cfx == 4 * (x < 0) + 2 * (side < 0) + (q[4] < 0)


def test_a_boundary_is_named(kr6):
    near = _kuka(kr6, (0, -90, 90, 0, 0.4, 0)).near
    assert any("axis 5 at 0.40 deg" in n for n in near)
    assert _kuka(kr6, (12, -80, 95, 33, 40, 51)).near == ()


@pytest.fixture(scope="module")
def ur5():
    return load_robot(RobotSpec(require(UR5), (SHARE,), FRAMES))


def test_an_offset_wrist_has_no_wrist_centre(ur5):
    with pytest.raises(NotASixAxisArmError, match="axes 4, 5 and 6 do not meet"):
        arm_configuration(ur5, JointMap.identity(6), np.zeros(6), ABB_ZERO)


def _table(robot, look: np.ndarray) -> tuple[CorrectionTable, dict]:
    """One task location where the robot stands at ``look``, corrected by 1.5 mm and 0.1 deg."""
    tcp = robot.fk(look, "tcp")
    task = TaskLocation("pick", tcp, 100.0, None)
    measured = transform_from_xyz_rpy([1.5, -0.8, 0.6], [0.1, -0.05, 0.02]) @ tcp
    table = CorrectionTable()
    table.add(
        Correction(
            "pick",
            tcp,
            measured,
            np.array([1.5, -0.8, 0.6]),
            np.array([0.1, -0.05, 0.02]),
            np.full(3, 0.1),
            np.full(3, 0.01),
            look,
            0.3,
            8,
        )
    )
    return table, {"pick": task}


def test_a_krl_listing_carries_the_status_and_turn_of_the_arm_at_the_corrected_target(kr6):
    look = np.array(
        [-25.0, -110.0, 100.0, -20.0, -50.0, -150.0]
    )  # basic area, A5 negative; A1, A2, A4, A5 and A6 negative
    table, tasks = _table(kr6, look)
    text = controller_listing("krl", table, tasks, robot=kr6)
    found = re.search(r"DECL GLOBAL POS pick_c=\{X [^}]*,S (\d+),T (\d+)\}", text)
    assert found, text
    assert (int(found.group(1)), int(found.group(2))) == kuka_status_turn(_kuka(kr6, look)) == (6, 59)
    assert "S and T from the arm at this target" in text
    # without the robot: a FRAME, and S and T left to be taught, said so
    bare = controller_listing("krl", table, tasks)
    assert "DECL GLOBAL FRAME pick_c=" in bare and "S and T must be taught (no robot given)" in bare


def test_a_rapid_listing_carries_the_confdata_of_the_arm_at_the_corrected_target(irb1200):
    look = np.array([120.0, 20.0, -40.0, -100.0, -60.0, 200.0])
    table, tasks = _table(irb1200, look)
    text = controller_listing("rapid", table, tasks, robot=irb1200)
    found = re.search(r"CONST robtarget pick_c := \[\[[^\]]*\],\[[^\]]*\],\[(-?\d+),(-?\d+),(-?\d+),(-?\d+)\],", text)
    assert found, text
    assert tuple(int(v) for v in found.groups()) == abb_confdata(_abb(irb1200, look)) == (1, -2, 2, 1)


def test_a_urscript_listing_gives_the_joints_the_controller_solves_near(ur5):
    look = np.array([10.0, -100.0, 80.0, -70.0, -90.0, 30.0])
    table, tasks = _table(ur5, look)
    text = controller_listing("urscript", table, tasks, robot=ur5)
    qnear = [float(v) for v in re.search(r"global pick_c_qnear = \[([^\]]*)\]", text).group(1).split(",")]
    assert np.allclose(
        np.degrees(qnear), look, atol=1.0
    )  # the corrected target is 1.8 mm away: the same branch, a little turned
    assert "movej(get_inverse_kin(pick_c, qnear=pick_c_qnear))" in text
