"""Vendor robot descriptions load as they are shipped: the UR5 (6 axes, tool0, the base/base_link
trap) and the Franka Panda (7 axes, prismatic fingers), with package:// meshes in DAE and STL."""

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.frames import make_transform, pose_difference, transform_from_xyz_rpy
from calib_core.robot import RobotModelError, solve_ik
from calib_core.robot.model import load_robot
from calib_core.robot.spec import NewFrame, RobotSpec
from calib_core.robot.visuals import RobotVisuals
from tests.vendor_robots import PANDA, SHARE, UR5, require


def _ur5(**frames):
    return load_robot(RobotSpec(require(UR5), (SHARE,), {"base": "base", "flange": "tool0", **frames}))


def test_ur5_forward_kinematics_matches_its_dh_parameters():
    # UR5 DH (Universal Robots): d1 89.159, a2 -425, a3 -392.25, d4 109.15, d5 94.65, d6 82.3 mm. At zero joints
    # the tool flange sits at (a2 + a3, -(d4 + d6), d1 - d5) in UR's base frame, its z along -y.
    robot = _ur5()
    tool0 = robot.fk(np.zeros(6), "flange")
    assert np.allclose(tool0[:3, 3], [-817.25, -191.45, -5.491], atol=1e-3)
    assert np.allclose(tool0[:3, 2], [0.0, -1.0, 0.0], atol=1e-9)
    # The same robot with poses in the URDF root (base_link): x and y flip, as UR's controller does not report.
    root = load_robot(RobotSpec(UR5, (SHARE,), {"base": None, "flange": "tool0"})).fk(np.zeros(6), "flange")
    assert np.allclose(root[:3, 3], [817.25, 191.45, -5.491], atol=1e-3)
    assert np.allclose(transform_from_xyz_rpy([0, 0, 0], [0, 0, 180]) @ tool0, root, atol=1e-9)


def test_ur5_vendor_meshes_load_with_their_links():
    robot = _ur5()
    visuals = RobotVisuals.from_robot(robot)
    names = [g.name for g in visuals.geometry_model.geometryObjects]
    assert len(names) == 7 and names[0].startswith("base_link")
    assert sum(len(m.faces) for m in visuals.meshes) > 50_000  # the vendor DAE meshes, not primitives
    # The shoulder mesh (about 120 mm across) is in mm, centred on the shoulder joint.
    shoulder = visuals.meshes[1]
    assert 100 < np.ptp(shoulder.vertices[:, 0]) < 150
    items = visuals.scene_items(np.zeros(6))
    wrist3 = items[-1].item2world
    assert np.linalg.norm(wrist3[:3, 3] - robot.fk(np.zeros(6), "wrist_3_link")[:3, 3]) < 1e-6
    collision = RobotVisuals.from_robot(robot, "collision")
    assert len(collision.meshes) == 8  # the seven links and the box of ee_link


def test_new_frames_are_placed_on_their_parent_without_editing_the_urdf():
    tcp = transform_from_xyz_rpy([0, 0, 150], [0, 0, 0])
    cam = transform_from_xyz_rpy([70, 0, 40], [0, -12, 0])
    robot = _ur5(tcp=NewFrame("tool0", tcp), camera=NewFrame("tool0", cam))
    q = np.array([10.0, -80.0, 70.0, -60.0, -90.0, 30.0])
    flange = robot.fk(q, "flange")
    assert np.allclose(robot.fk(q, "tcp"), flange @ tcp, atol=1e-9)
    assert np.allclose(robot.fk(q, "camera"), flange @ cam, atol=1e-9)
    assert robot.roles["flange"] == "tool0"


def test_panda_seven_axes_and_held_prismatic_fingers():
    spec = RobotSpec(
        require(PANDA),
        (SHARE,),
        {"flange": "panda_hand", "tcp": NewFrame("panda_hand", make_transform(np.eye(3), [0, 0, 103.4]))},
        held_joints={"panda_finger_joint1": 20.0, "panda_finger_joint2": 20.0},
    )
    robot = load_robot(spec)
    assert robot.n_joints == 7 and robot.joint_units == ["deg"] * 7
    assert robot.joint_names[-1] == "panda_joint7"
    with pytest.raises(RobotModelError, match="expected 7 joint values"):
        robot.fk(np.zeros(6))
    # Held at 20 mm: each finger stands 20 mm off the hand's axis.
    full = load_robot(RobotSpec(PANDA, (SHARE,), {"flange": "panda_hand"}, held_joints={}))
    assert full.n_joints == 9 and full.joint_units[-2:] == ["mm", "mm"]
    assert np.allclose(full.upper_limits_deg[-2:], [40.0, 40.0])
    q7 = np.array([0.0, -30.0, 0.0, -120.0, 0.0, 90.0, 45.0])
    for opening in (0.0, 20.0, 35.0):
        q9 = np.r_[q7, opening, opening]
        hand = full.fk(q9, "panda_hand")
        left = np.linalg.inv(hand) @ full.fk(q9, "panda_leftfinger")
        assert left[1, 3] == pytest.approx(opening, abs=1e-9)  # prismatic along the hand's y, in mm
    hand_held = np.linalg.inv(robot.fk(q7, "panda_hand")) @ robot.fk(q7, "panda_leftfinger")
    assert hand_held[1, 3] == pytest.approx(20.0, abs=1e-9)


def test_panda_jacobian_matches_finite_differences_in_user_units():
    robot = load_robot(
        RobotSpec(
            require(PANDA),
            (SHARE,),
            {"flange": "panda_hand", "tcp": "panda_hand_tcp"},
            held_joints={"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0},
        )
    )
    q = np.array([20.0, -35.0, 10.0, -110.0, 15.0, 80.0, 30.0])
    J = robot.jacobian(q, "tcp") * robot.internal_per_user  # per degree
    h = 1e-4
    for j in range(7):
        dq = np.zeros(7)
        dq[j] = h
        d_pos, d_rot = pose_difference(robot.fk(q + dq, "tcp"), robot.fk(q - dq, "tcp"))
        assert np.allclose(J[:3, j], d_pos / (2 * h), atol=1e-5)
        assert np.allclose(J[3:, j], np.radians(d_rot) / (2 * h), atol=1e-7)


def test_five_driven_axes_and_ik_round_trip():
    # The UR5 with its last wrist joint held: a 5-axis arm.
    robot = load_robot(
        RobotSpec(
            require(UR5),
            (SHARE,),
            {"base": "base", "flange": "tool0", "tcp": NewFrame("tool0", make_transform(np.eye(3), [0, 0, 150]))},
            held_joints={"wrist_3_joint": 30.0},
        )
    )
    assert robot.n_joints == 5
    q = np.array([20.0, -70.0, 80.0, -100.0, -80.0])
    target = robot.fk(q, "tcp")
    found = solve_ik(robot, target, q + np.array([5.0, -5.0, 5.0, 5.0, -5.0]))
    d, r = pose_difference(robot.fk(found.q_deg, "tcp"), target)
    assert np.linalg.norm(d) < 1e-3 and np.linalg.norm(r) < 1e-4


def test_a_continuous_joint_counts_once_in_degrees(tmp_path):
    urdf = tmp_path / "spinner.urdf"
    urdf.write_text("""<robot name="spinner">
  <link name="base"/><link name="arm"/><link name="slider"/><link name="tip"/>
  <joint name="spin" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="0.5 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" velocity="0.1" effort="1"/></joint>
  <joint name="fix" type="fixed"><parent link="slider"/><child link="tip"/><origin xyz="0.1 0 0"/></joint>
</robot>""")
    robot = load_robot(RobotSpec(urdf, (), {"tcp": "tip"}))
    assert robot.n_joints == 2 and robot.joint_units == ["deg", "mm"]
    assert robot.lower_limits_deg[0] == -np.inf and robot.upper_limits_deg[1] == pytest.approx(200.0)
    assert robot.max_speed_deg_s[1] == pytest.approx(100.0)  # 0.1 m/s
    assert np.allclose(robot.fk([370.0, 50.0], "tcp"), robot.fk([10.0, 50.0], "tcp"), atol=1e-9)
    tip = robot.fk([90.0, 50.0], "tcp")[:3, 3]
    assert np.allclose(tip, [0.0, 650.0, 0.0], atol=1e-9)  # 500 + 50 mm slide + 100 mm, turned 90 deg


def test_a_missing_mesh_names_the_urdf_the_link_and_the_places_looked_in(tmp_path):
    copy = tmp_path / "ur5.urdf"
    copy.write_text(require(UR5).read_text())
    with pytest.raises(FileFormatError) as info:
        load_robot(RobotSpec(copy, (tmp_path,)))
    message = str(info.value)
    assert str(copy) in message and "link 'base_link' visual mesh" in message
    assert "package://example-robot-data/robots/ur_description/meshes/ur5/visual/base.dae" in message
    assert str(tmp_path / "example-robot-data" / "robots") in message  # where it looked


def test_a_xacro_file_is_expanded_and_a_broken_one_named(tmp_path):
    good = tmp_path / "arm.urdf.xacro"
    good.write_text("""<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="upper" value="0.4"/>
  <xacro:macro name="link_with_box" params="name length">
    <link name="${name}"><visual><origin xyz="0 0 ${length/2}"/>
      <geometry><box size="0.05 0.05 ${length}"/></geometry></visual></link>
  </xacro:macro>
  <xacro:link_with_box name="base_link" length="0.1"/>
  <xacro:link_with_box name="upper_arm" length="${upper}"/>
  <link name="flange"/>
  <joint name="shoulder" type="revolute"><parent link="base_link"/><child link="upper_arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="2" effort="10"/></joint>
  <joint name="to_flange" type="fixed"><parent link="upper_arm"/><child link="flange"/>
    <origin xyz="0 0 ${upper}"/></joint>
</robot>""")
    robot = load_robot(RobotSpec(good, (), {"tcp": "flange"}))
    assert robot.n_joints == 1
    assert np.allclose(robot.fk([0.0], "flange")[:3, 3], [0.0, 0.0, 500.0])
    assert len(RobotVisuals.from_robot(robot).meshes) == 2
    bad = tmp_path / "bad.xacro"
    bad.write_text(good.read_text().replace("${upper}", "${lower}"))
    with pytest.raises(FileFormatError, match="cannot expand xacro") as info:
        load_robot(bad)
    assert str(bad) in str(info.value)


def test_meshes_from_the_disk_cache_are_the_loaders_own(tmp_path, monkeypatch):
    import calib_core.robot.visuals as visuals_module
    from calib_core.robot import mesh_cache

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    spec = RobotSpec(
        require(PANDA),
        (SHARE,),
        {"flange": "panda_hand", "tcp": "panda_hand_tcp"},
        held_joints={"panda_finger_joint1": 10.0, "panda_finger_joint2": 10.0},
    )
    q = np.array([10.0, -30.0, 5.0, -100.0, 20.0, 70.0, 30.0])
    robot = load_robot(spec)
    fresh = RobotVisuals.from_robot(robot)  # through Pinocchio's loader: fills the cache
    assert len(list(mesh_cache.cache_folder().glob("*.npz"))) >= 10
    visuals_module._GEOMETRY_CACHE.clear()
    cached = RobotVisuals.from_robot(load_robot(spec))  # the description with placeholders, meshes from disk
    assert id(cached.geometry_model) in visuals_module._CACHED_MESHES
    for a, b, pa, pb, ga, gb in zip(
        fresh.meshes,
        cached.meshes,
        fresh.poses(q),
        cached.poses(q),
        fresh.geometry_model.geometryObjects,
        cached.geometry_model.geometryObjects,
    ):
        assert ga.name == gb.name and np.allclose(ga.meshColor, gb.meshColor)
        assert np.array_equal(a.faces, b.faces) and np.allclose(a.vertices, b.vertices)
        assert np.allclose(pa, pb, atol=1e-9)
