"""The operator core drives a robot over ROS 2 as it drives one over videocal's own link: samples into its
joints, a previewed move through the trajectory controller, Stop, and 'pose unknown' when joint states stop."""

import time

import numpy as np

from calib_core.link.link_types import LinkState
from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore
from calib_core.operator.motion import Motion
from calib_core.operator.site import RealSite
from calib_core.ros2.joint_units import user_per_si
from videocal_sim.ros2_arm import SimulatedRos2Arm


def _wait(predicate, timeout_s=15.0):
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def test_go_to_task_over_ros2_and_pose_unknown_when_the_states_stop(domain):
    cell = Cell.open()
    robot = cell.robot
    start = cell.home_joints + 3.0
    arm = SimulatedRos2Arm(robot.joint_names, user_per_si(robot.joint_units), robot.lower_limits_deg, robot.upper_limits_deg, start,
                           rate_hz=100.0, domain=domain).start()
    core = OperatorCore(cell, RealSite("ros2:///joint_states?stale_after_s=0.3", controller_options={"speed_deg_s": 90}))
    try:
        assert core.start_controller() == "ros2:///joint_states?stale_after_s=0.3"
        assert _wait(lambda: core.link_up and np.allclose(core.joints_deg, start, atol=1e-6))
        handle = core.go_to_task(approach=True, wait=True, confirmed=True)
        assert handle.error is None and core.motion.motion is Motion.ARRIVED
        # The trajectory carried the model's joints by URDF name: the arm stands where the core aimed.
        assert np.allclose(arm.position(time.monotonic()), handle.joints_deg, atol=1e-6)
        assert np.allclose(core.joints_deg, handle.joints_deg, atol=0.05)
        arm.close()  # the driver goes away: no more joint states
        assert _wait(lambda: core.link.state is LinkState.STALE and not core.link_up, 5.0)
    finally:
        core.close()
