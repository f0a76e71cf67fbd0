"""Camera to tool: the TCP from the camera by a grasp on a surveyed fixture (known answers), and the
simulated compliance that puts the true TCP on the pin."""

import numpy as np
import pytest

from calib_core.frames import invert, pose_difference, transform_from_xyz_rpy
from calib_core.robot import solve_ik
from calib_core.robot_calibration.camera_to_tool import CameraToToolError, Grasp, camera_to_tool, with_tool
from calib_core.robot_calibration.parameters import CorrectedRobot
from videocal_sim.compliant_grasp import COMPLIANCE_MM, grasp_joints
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors
from calib_core.workcell import load_workcell


def test_a_grasp_gives_the_tool_in_the_camera_frame_exactly():
    """A robot whose TCP sits elsewhere than the model says (2 mm, 0.3 deg): grasps at two fixtures,
    with the camera placed by the robot's own (exact) model, give its true tcp2cam; the model with
    that tool puts the TCP right at a third pose."""
    cell = load_workcell()
    model = cell.load_robot()
    truth = CorrectedRobot(model)
    truth.set(np.random.default_rng(2).normal(0, 0.3, truth.layout.size))
    real = truth.robot
    real.set_frame_placement(
        "tcp", model.frame_placement("tcp") @ transform_from_xyz_rpy([1.2, -1.5, 0.6], [0.2, -0.1, 0.15])
    )
    grasps = []
    for task in list(cell.task_locations.values())[:2]:
        q = solve_ik(real, task.tcp2base, np.array(cell.home_joints_deg, float)).q_deg
        grasps.append(Grasp(task.name, q, task.tcp2base))
    # The camera's pose comes from the calibrated model, which here knows the joints and the camera but not the tool.
    known = CorrectedRobot(model)
    known.set(truth.parameters)
    tool = camera_to_tool(known.robot, grasps)
    true_tcp2cam = invert(real.frame_placement("camera")) @ real.frame_placement("tcp")
    d, r = pose_difference(tool.tcp2cam, true_tcp2cam)
    assert np.linalg.norm(d) < 1e-3 and np.linalg.norm(r) < 1e-4 and tool.spread_mm < 1e-3
    fixed = with_tool(known.robot, tool.tcp2cam)
    q = np.array([10.0, -20.0, 30.0, 5.0, 40.0, -15.0])
    d, r = pose_difference(fixed.fk(q, "tcp"), real.fk(q, "tcp"))
    assert np.linalg.norm(d) < 1e-3 and np.linalg.norm(r) < 1e-4
    d0, _ = pose_difference(known.robot.fk(q, "tcp"), real.fk(q, "tcp"))
    assert np.linalg.norm(d0) > 1.0  # without the grasp the tool is as wrong as the model's


def test_no_grasp_and_a_camera_on_another_joint_are_refused():
    model = load_workcell().load_robot()
    with pytest.raises(CameraToToolError, match="no grasp"):
        camera_to_tool(model, [])
    with pytest.raises(CameraToToolError, match="different joints"):
        with_tool(model, np.eye(4), tcp_frame="tcp", camera_frame=model.model.frames[2].name)


def test_the_simulated_compliance_puts_the_true_tcp_on_the_pin():
    bed = TestBed.create(errors=RobotErrors.typical(0))
    for k, task in enumerate(bed.workcell.task_locations.values()):
        q = grasp_joints(bed, task.tcp2base, k)
        d, r = pose_difference(bed.true_robot.fk(q, "tcp"), task.tcp2base)
        assert np.linalg.norm(d) <= COMPLIANCE_MM + 1e-3 and np.linalg.norm(r) < 1e-4
        d_model, _ = pose_difference(bed.model_robot.fk(q, "tcp"), task.tcp2base)
        assert np.linalg.norm(d_model) > 1.0  # the model says the TCP is elsewhere: the robot's error


def test_the_tool_s_covariance_holds_each_grasped_fixture_s_survey_and_the_camera_s():
    """Known answers: one grasp with the survey's 0.05 mm per axis gives that much in position in any
    axes; two grasps of different fixtures half of it; a camera covariance adds the lever arm's share;
    and the Monte Carlo of fixtures moved within their survey matches the covariance."""
    cell = load_workcell()
    robot = cell.load_robot()
    home = np.array(cell.home_joints_deg, float)
    tasks = list(cell.task_locations.values())[:2]
    grasps = [Grasp(t.name, solve_ik(robot, t.tcp2base, home).q_deg, t.tcp2base) for t in tasks]
    assert camera_to_tool(robot, grasps).covariance is None
    one = camera_to_tool(robot, grasps[:1], placement_sigma_mm=0.05)
    cam2base = robot.fk(grasps[0].joints_deg, "camera")
    assert np.allclose(one.covariance_in_base(cam2base)[:3, :3], 0.05**2 * np.eye(3), atol=1e-12)
    assert np.allclose(one.covariance[3:, 3:], 0.0)
    two = camera_to_tool(robot, grasps, placement_sigma_mm=0.05)
    assert np.isclose(np.trace(two.covariance[:3, :3]), 3 * 0.05**2 / 2)
    turn = np.diag([0.0, 0.0, 0.0, 0.2, 0.2, 0.2]) ** 2  # the camera turned 0.2 mrad per axis: the TCP swings
    with_camera = camera_to_tool(robot, grasps[:1], placement_sigma_mm=0.05, camera_covariance=lambda q: turn)
    assert np.trace(with_camera.covariance[:3, :3]) > np.trace(one.covariance[:3, :3])
    assert np.allclose(np.sqrt(np.diag(with_camera.covariance[3:, 3:])), np.degrees(0.2e-3), rtol=1e-9)
    # Monte Carlo: the fixtures truly stand within the survey, the grasps put the TCP there, and the
    # tool computed from the surveyed places is off by what the covariance says
    rng = np.random.default_rng(0)
    surveyed = two.tcp2cam[:3, 3]
    errors = []
    for _ in range(2000):
        true_grasps = []
        for g in grasps:
            moved = g.tcp2base.copy()
            moved[:3, 3] += rng.normal(0, 0.05, 3)
            true_grasps.append(Grasp(g.name, g.joints_deg, moved))
        errors.append(surveyed - camera_to_tool(robot, true_grasps).tcp2cam[:3, 3])
    empirical = np.cov(np.array(errors).T)
    assert np.allclose(empirical, two.covariance[:3, :3], atol=0.1 * 0.05**2)
