"""Forward kinematics against hand-computed poses, Jacobians against finite differences, IK round trips."""

import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.frames import make_transform
from calib_core.robot import RobotModelError, UnknownFrameError, UnreachableTargetError, load_robot, solve_ik


@pytest.fixture(scope="module")
def robot():
    return load_robot()


def test_zero_pose_matches_the_drawing(robot):
    # Shoulder 150 mm out and 600 mm up, upper arm 700, elbow offset 110, forearm 300 + 450, wrist 110.
    assert np.allclose(robot.fk(np.zeros(6), "flange")[:3, 3], [1010.0, 0.0, 1410.0], atol=1e-9)
    tcp = robot.fk(np.zeros(6), "tcp")
    assert np.allclose(tcp[:3, 3], [1190.0, 0.0, 1410.0], atol=1e-6)
    assert np.allclose(tcp[:3, 2], [1.0, 0.0, 0.0], atol=1e-9)  # approach axis along +x
    cam = robot.fk(np.zeros(6), "camera")
    assert np.allclose(cam[:3, 3], [1070.0, 0.0, 1520.0], atol=1e-9)  # 60 mm out and 110 mm up from the flange
    assert np.allclose(cam[:3, 2], [np.cos(np.radians(30)), 0.0, -np.sin(np.radians(30))], atol=1e-7)  # 30 deg down


def test_joint_1_turns_the_arm_about_z(robot):
    assert np.allclose(robot.fk([90, 0, 0, 0, 0, 0], "flange")[:3, 3], [0.0, 1010.0, 1410.0], atol=1e-9)


def test_joint_2_tips_the_upper_arm(robot):
    # Joint 2 at +90 deg (about y) lays the upper arm forward: elbow at (150 + 700, 0, 600).
    flange = robot.fk([0, 90, 0, 0, 0, 0], "flange")[:3, 3]
    assert np.allclose(flange, [150 + 700 + 110, 0.0, 600 - 860], atol=1e-9)


def test_jacobian_matches_finite_differences(robot):
    q = np.array([-20.0, 30.0, -40.0, 10.0, 35.0, -15.0])
    J = robot.jacobian(q, "tcp")
    T0 = robot.fk(q, "tcp")
    h = 1e-6
    for k in range(6):
        dq = np.zeros(6)
        dq[k] = np.degrees(h)
        Tp = robot.fk(q + dq, "tcp")
        Tm = robot.fk(q - dq, "tcp")
        v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ T0[:3, :3].T
        w = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        assert np.allclose(J[:3, k], v, rtol=1e-5, atol=1e-4)
        assert np.allclose(J[3:, k], w, atol=1e-6)


def test_ik_round_trip_and_closest_solution(robot):
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = rng.uniform(-60, 60, 6)
        q[1] = rng.uniform(-20, 60)
        target = robot.fk(q, "tcp")
        sol = solve_ik(robot, target, q + rng.normal(0, 3, 6))
        assert np.allclose(robot.fk(sol.q_deg, "tcp"), target, atol=1e-3)
        assert np.max(np.abs(sol.q_deg - q)) < 1e-3  # the branch of the current joints, not another one
        assert robot.within_limits(sol.q_deg).all()


def test_unreachable_target_and_unknown_frame(robot):
    with pytest.raises(UnreachableTargetError, match="cannot reach") as info:
        solve_ik(robot, make_transform(np.eye(3), [5000.0, 0.0, 1000.0]), extra_seeds=3)
    assert info.value.best[0] > 1000
    with pytest.raises(UnknownFrameError, match="no frame 'wrist_cam'.*known frames: .*camera"):
        robot.fk(np.zeros(6), "wrist_cam")
    with pytest.raises(RobotModelError, match="expected 6 joint values"):
        robot.fk(np.zeros(5))


def test_bad_urdf_files(tmp_path):
    with pytest.raises(FileFormatError, match="no such URDF"):
        load_robot(tmp_path / "missing.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'></robot>")
    with pytest.raises(FileFormatError, match="bad.urdf"):
        load_robot(bad)
