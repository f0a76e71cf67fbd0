"""The operator core drives a robot over ROS 2 as it drives one over videocal's own link: samples into its
joints, a previewed move through the trajectory controller, Stop, and 'pose unknown' when joint states stop."""

import time

import numpy as np

from calib_core.connectors.link_types import LinkState
from calib_core.operator.cell import Cell
from calib_core.operator.core import OperatorCore
from calib_core.operator.motion import Motion
from calib_core.operator.site import RealSite
from calib_core.ros2.joint_units import user_per_si
from videocal_sim.ros2_arm import SimulatedRos2Arm
from tests.waiting import wait_until


def test_go_to_task_over_ros2_and_pose_unknown_when_the_states_stop(domain):
    cell = Cell.open()
    robot = cell.robot
    start = cell.home_joints + 3.0
    arm = SimulatedRos2Arm(
        robot.joint_names,
        user_per_si(robot.joint_units),
        robot.lower_limits_deg,
        robot.upper_limits_deg,
        start,
        rate_hz=100.0,
        domain=domain,
    ).start()
    core = OperatorCore(
        cell, RealSite("ros2:///joint_states?stale_after_s=0.3", controller_options={"speed_deg_s": 90})
    )
    try:
        assert core.start_controller() == "ros2:///joint_states?stale_after_s=0.3"
        assert wait_until(lambda: core.link_up and np.allclose(core.joints_deg, start, atol=1e-6))
        handle = core.moves.go_to_task(approach=True, wait=True, confirmed=True)
        assert handle.error is None and core.motion.motion is Motion.ARRIVED
        # The trajectory carried the model's joints by URDF name: the arm stands where the core aimed.
        assert np.allclose(arm.position(time.monotonic()), handle.joints_deg, atol=1e-6)
        assert np.allclose(core.joints_deg, handle.joints_deg, atol=0.05)
        arm.close()  # the driver goes away: no more joint states
        assert wait_until(lambda: core.link.state is LinkState.STALE and not core.link_up, 5.0)
    finally:
        core.close()


def test_the_camera_mounting_and_targets_on_tf_static_for_a_late_subscriber(domain):
    """tf2's convention: one TFMessage with every static transform, transient local: a subscriber that joins
    later still gets the latest set; a new camera mounting is published again."""
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from scipy.spatial.transform import Rotation

    from calib_core.frames import concat, invert
    from calib_core.ros2 import messages as msg
    from calib_core.ros2.wire import static_tf_qos

    cell = Cell.open()
    robot = cell.robot
    arm = SimulatedRos2Arm(
        robot.joint_names,
        user_per_si(robot.joint_units),
        robot.lower_limits_deg,
        robot.upper_limits_deg,
        cell.home_joints,
        rate_hz=50.0,
        domain=domain,
    ).start()
    core = OperatorCore(cell, RealSite("ros2:///joint_states"))
    try:
        core.start_controller()
        mounting = concat(
            robot.fk(cell.home_joints, "camera"), invert(robot.fk(cell.home_joints, "flange"))
        )  # cam2base, base2flange
        # the same mounting a second way: both frames' placements on their common parent joint
        assert np.allclose(
            mounting, np.linalg.inv(robot.frame_placement("flange")) @ robot.frame_placement("camera"), atol=1e-9
        )
        moved = mounting.copy()
        moved[:3, 3] += [1.5, -2.0, 0.5]
        core.vision.apply_cam2flange(moved)
        peer = DomainParticipant(domain)  # joins after both publications
        reader = DataReader(peer, Topic(peer, "rt/tf_static", msg.TFMessage), qos=static_tf_qos())
        got = []
        assert wait_until(lambda: got.extend(reader.take()) or got, 10.0)
        by_child = {t.child_frame_id: t for t in got[-1].transforms}
        camera = by_child["videocal_camera_optical_frame"]  # the name the launch file, URDF and bag use too
        assert camera.header.frame_id == "flange"
        t = camera.transform.translation
        assert np.allclose([t.x, t.y, t.z], moved[:3, 3] / 1000.0, atol=1e-9)
        r = camera.transform.rotation
        assert np.allclose(Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix(), moved[:3, :3], atol=1e-9)
        task = next(iter(cell.workcell.task_locations.values()))
        target = by_child[f"videocal/{task.name}"]
        assert target.header.frame_id == "base_link"
        assert np.allclose(
            [
                target.transform.translation.x * 1000,
                target.transform.translation.y * 1000,
                target.transform.translation.z * 1000,
            ],
            task.tcp2base[:3, 3],
            atol=1e-6,
        )
    finally:
        core.close()
        arm.close()
