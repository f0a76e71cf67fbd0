"""The ROS 2 controller connector against a publisher of our own (its own IDL, written from the ROS message
definitions, not videocal's) and against the simulated ros2_control arm."""

import math
import time
from dataclasses import dataclass

import numpy as np
import pytest
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import float64, int32, sequence, uint32
from cyclonedds.pub import DataWriter
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState, MoveError
from calib_core.ros2.trajectory_connector import Ros2TrajectoryController
from videocal_sim.ros2_arm import SimulatedRos2Arm
from tests.waiting import wait_until


# --- sensor_msgs/msg/JointState as the ROS 2 definitions give it, written here on their own ---------
@dataclass
class Stamp(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Hdr(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Stamp
    frame_id: str


@dataclass
class Joints(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Hdr
    name: sequence[str]
    position: sequence[float64]
    velocity: sequence[float64]
    effort: sequence[float64]


NAMES = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "slide")
UNITS = ("deg",) * 5 + ("mm",)


def _context(**options):
    return ControllerContext(NAMES, UNITS, JointMap.identity(6), 100.0, options)


def test_joint_states_by_name_in_si_become_the_cells_joints_with_their_stamp(domain):
    dp = DomainParticipant(domain)
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile, Policy.History.KeepLast(10)
    )
    writer = DataWriter(dp, Topic(dp, "rt/joint_states", Joints), qos=qos)
    link = open_controller("ros2:///joint_states", _context())
    assert isinstance(link, Ros2TrajectoryController)
    got = []
    link.sample_received.connect(got.append)
    link.start()
    try:
        assert wait_until(lambda: writer.get_publication_matched_status().current_count > 0)
        # Another order, an extra gripper joint, radians and metres, a stamp of the publisher's clock.
        order = ["slide", "gripper", "wrist_2", "elbow", "shoulder_pan", "wrist_1", "shoulder_lift"]
        values = {
            "slide": 0.125,
            "gripper": 0.02,
            "wrist_2": -math.pi / 2,
            "elbow": 1.0,
            "shoulder_pan": 0.1,
            "wrist_1": 0.0,
            "shoulder_lift": -0.5,
        }
        writer.write(Joints(Hdr(Stamp(1_700_000_000, 250_000_000), "base"), order, [values[n] for n in order], [], []))
        # A message with the arm's joints missing (a gripper's own states) is not the arm's sample.
        writer.write(Joints(Hdr(Stamp(1_700_000_000, 260_000_000), "base"), ["gripper"], [0.01], [], []))
        # An older stamp after a newer one is not the robot now.
        writer.write(Joints(Hdr(Stamp(1_700_000_000, 200_000_000), "base"), order, [values[n] for n in order], [], []))
        assert wait_until(
            lambda: link.stats_snapshot()["wrong_joint_count"] == 1 and link.stats_snapshot()["backwards_samples"] == 1
        )
        assert len(got) == 1 and link.state is LinkState.UP
        sample = got[0].sample
        assert sample.t_ms == 1_700_000_000_250
        expected = [math.degrees(0.1), math.degrees(-0.5), math.degrees(1.0), 0.0, -90.0, 125.0]
        assert np.allclose(sample.joints_deg, expected, atol=1e-9)
    finally:
        link.close()


def test_no_joint_states_is_stale_and_the_reason_says_where(domain):
    link = open_controller("ros2:///arm/joint_states?stale_after_s=0.2", _context())
    states = []
    link.state_changed.connect(lambda state, why: states.append((state, why)))
    link.start()
    try:
        assert link.state is LinkState.CONNECTING and "/arm/joint_states" in states[0][1]
        handle = link.move_joints([0.0] * 6)
        assert not handle.sent and "connecting" in str(handle.error)
    finally:
        link.close()


@pytest.fixture
def arm(domain):
    arm = SimulatedRos2Arm(
        NAMES,
        [180 / math.pi] * 5 + [1000.0],
        [-170.0] * 5 + [0.0],
        [170.0] * 5 + [500.0],
        [0, -30, 60, 0, 45, 100],
        rate_hz=200.0,
        domain=domain,
        controller="arm_controller",
    ).start()
    yield arm
    arm.close()


@pytest.fixture(params=["topic", "action"])
def interface(request):
    """Each move test through the controller's topic and through its FollowJointTrajectory action."""
    return request.param


def _connected(interface="topic", **options):
    link = open_controller(
        "ros2:///joint_states", _context(controller="arm_controller", interface=interface, **options)
    ).start()
    ready = (
        (lambda: link._goals.client.server_ready())
        if interface == "action"
        else (lambda: link._writer.get_publication_matched_status().current_count > 0)
    )
    assert wait_until(lambda: link.state is LinkState.UP and ready())
    return link


def test_a_move_through_the_trajectory_controller_ends_at_its_target(arm, interface):
    link = _connected(interface, speed_deg_s=100)
    try:
        target = [10.0, -20.0, 50.0, 5.0, 40.0, 150.0]
        handle = link.move_joints(target, timeout_s=20)
        assert handle.sent and handle.acked
        handle.wait(20)
        assert np.allclose(link.latest.joints_deg, target, atol=0.05)
        # (the move ends when the joints are within the link's tolerance; the arm settles its last thousandth of a
        # degree after, later still on a loaded machine)
        assert wait_until(lambda: np.allclose(arm.position(time.monotonic()), target, atol=1e-6))
        if interface == "action":
            assert arm.action.accepted >= 1 and arm.trajectories == 0  # goals, none on the topic
        else:
            assert arm.trajectories >= 1 and arm.action.accepted == 0
    finally:
        link.close()


def test_stop_holds_the_arm_where_it_stands(arm, interface):
    link = _connected(interface, speed_deg_s=20)
    try:
        handle = link.move_joints([60.0, -30.0, 60.0, 0.0, 45.0, 100.0], timeout_s=20)
        assert wait_until(lambda: link.latest.joints_deg[0] > 5.0)
        assert link.stop()
        with pytest.raises(MoveError, match="STOPPED"):
            handle.wait(1)
        assert wait_until(lambda: arm._plan is not None and arm._plan[1][-1] <= 0.11 or arm._plan is None)
        time.sleep(0)  # the hold trajectory lasts 0.1 s; then the arm stands still
        assert wait_until(lambda: arm._plan is None, 2.0)
        held = arm.position(time.monotonic())[0]
        assert 5.0 < held < 30.0  # stopped on the way, far from 60
        assert wait_until(lambda: abs(link.latest.joints_deg[0] - held) < 1e-6, 2.0)
        if interface == "action":
            assert wait_until(lambda: arm.action.cancelled == 1)  # Stop is the goal's cancel
    finally:
        link.close()


def test_a_move_with_no_controller_listening_is_not_sent(arm):
    link = open_controller("ros2:///joint_states", _context(controller="no_such_controller")).start()
    try:
        assert wait_until(lambda: link.state is LinkState.UP)
        handle = link.move_joints([0.0] * 5 + [100.0])
        assert not handle.sent
        assert "no trajectory controller subscribes to /no_such_controller/joint_trajectory" in str(handle.error)
        assert arm.trajectories == 0
    finally:
        link.close()


def test_the_arm_rejects_a_trajectory_past_its_limits(arm, interface):
    link = _connected(interface, speed_deg_s=1000)  # the first half second of the move already crosses the limit
    try:
        handle = link.move_joints([0, -30, 60, 0, 45, 900.0], timeout_s=1.0)  # slide limit 500 mm
        # through the action the controller's refusal ends the move at once, with its words
        with pytest.raises(MoveError, match="refused the goal" if interface == "action" else None):
            handle.wait(3)
        refused = arm.action.refused if interface == "action" else arm.rejected
        assert refused >= 1 and np.allclose(arm.position(time.monotonic()), [0, -30, 60, 0, 45, 100])
    finally:
        link.close()


_WORKSTATION = """
import sys, time
from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState
names = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "slide")
options = {"controller": "arm_controller", "speed_deg_s": 20, "horizon_s": 0.5, "interface": sys.argv[1]}
context = ControllerContext(names, ("deg",) * 5 + ("mm",), JointMap.identity(6), 100.0, options)
link = open_controller("ros2:///joint_states", context).start()
def matched():
    if sys.argv[1] == "action":
        return link._goals.client.server_ready()
    return link._writer.get_publication_matched_status().current_count > 0
while not (link.state is LinkState.UP and matched()):
    time.sleep(0.01)
handle = link.move_joints([80.0, -30.0, 60.0, 0.0, 45.0, 100.0], timeout_s=30)
print("moving", flush=True)
time.sleep(60)
"""


def test_a_workstation_that_dies_mid_move_stops_the_arm_within_the_horizon(arm, interface):
    """The dead-man: a one-point trajectory ran on to the target whatever became of the workstation.
    A real process, killed with SIGKILL mid-move (no Stop, no goodbye): the arm stops within the horizon's
    motion (0.5 s at 20 deg/s: 10 deg) of where it was, on the way, and stays there."""
    import signal
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    station = subprocess.Popen(
        [sys.executable, "-c", _WORKSTATION, interface], cwd=root, stdout=subprocess.PIPE, text=True
    )
    try:
        assert station.stdout.readline().strip() == "moving"
        assert wait_until(lambda: arm.position(time.monotonic())[0] > 20.0, 10.0)
        station.send_signal(signal.SIGKILL)
        station.wait(5)
        at_kill = arm.position(time.monotonic())[0]
        assert wait_until(lambda: arm._plan is None, 3.0)  # the last point given reached: the arm stands
        held = arm.position(time.monotonic())[0]
        assert at_kill <= held <= at_kill + 10.0 + 0.5  # 10 deg of motion at most (and a sample's worth)
        assert held < 60.0  # far from the 80 deg target it would have run on to
        assert arm.rejected == 0 and arm.plan_number >= 3  # streamed: renewed while it moved (topic messages or goals)
    finally:
        if station.poll() is None:
            station.kill()


def test_wrong_urls_and_options_are_named(domain):
    from calib_core.connectors.link_types import LinkError

    with pytest.raises(LinkError, match="has no host"):
        open_controller("ros2://robot/joint_states", _context())
    with pytest.raises(LinkError, match="unknown option"):
        open_controller("ros2:///joint_states?controler=x", _context())
    with pytest.raises(LinkError, match="speed_deg_s"):
        open_controller("ros2:///joint_states?speed_deg_s=fast", _context())
    with pytest.raises(LinkError, match="give the cell"):
        open_controller("ros2:///joint_states", ControllerContext((), (), JointMap.identity(0)))


def test_the_simulated_arm_refuses_an_empty_trajectory_as_the_controller_does():
    """ros2_controllers' joint_trajectory_controller logs "Empty trajectory received." and keeps its trajectory; a
    Stop must therefore be a trajectory that holds, which is what the connector sends."""
    from calib_core.ros2 import messages as msg

    arm = SimulatedRos2Arm(
        NAMES, [180 / math.pi] * 5 + [1000.0], [-360.0] * 5 + [0.0], [360.0] * 5 + [500.0], [0, -30, 60, 0, 45, 100]
    )
    point = msg.JointTrajectoryPoint(positions=[0.1, 0, 0, 0, 0, 0.1], time_from_start=msg.Duration.of_s(1.0))
    assert arm.follow(msg.JointTrajectory(msg.Header(), list(NAMES), [point]), 0.0) is None
    assert arm.follow(msg.JointTrajectory(msg.Header(), list(NAMES), []), 0.5) == "Empty trajectory received."
    assert np.allclose(arm.position(1.0), [math.degrees(0.1), 0, 0, 0, 0, 100.0])  # the first one ran on to its end


def test_a_move_ends_when_the_joint_states_stop_not_at_its_deadline(arm):
    """The arm's driver gone mid-move (measured through the 1.5 s far network before this: the move ran on to its
    60 s deadline while the link said stale)."""
    link = _connected(speed_deg_s=10)
    try:
        handle = link.move_joints([60, -30, 60, 0, 45, 100], timeout_s=60.0)
        assert wait_until(lambda: link.latest.joints_deg[0] > 1.0)
        arm.close()  # the driver gone: no joint states, no controller
        with pytest.raises(MoveError, match="the joint states stopped"):
            handle.wait(5.0)
        assert link.state is LinkState.STALE
        assert not link.move_joints([0, -30, 60, 0, 45, 100]).sent
    finally:
        link.close()


def test_joint_states_of_other_names_say_which_came_and_which_renaming_fits(domain):
    """`monitor` said "waiting for /joint_states" while hundreds of messages arrived whose names the cell's robot does
    not have (only the statistics counted them). The link's state now names what came and what is missing, and the
    renaming when the names are this robot's with a prefix."""
    dp = DomainParticipant(domain)
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.Durability.Volatile, Policy.History.KeepLast(10)
    )
    writer = DataWriter(dp, Topic(dp, "rt/joint_states", Joints), qos=qos)
    link = open_controller("ros2:///joint_states", _context())
    states = []
    link.state_changed.connect(lambda state, why: states.append((state, why)))
    link.start()
    try:
        assert wait_until(lambda: writer.get_publication_matched_status().current_count > 0)
        prefixed = [f"ur10e_{n}" for n in NAMES]
        writer.write(Joints(Hdr(Stamp(1_700_000_000, 0), "base"), prefixed, [0.0] * 6, [], []))
        assert wait_until(lambda: any("arrives without this cell's joints" in why for _, why in states))
        why = states[-1][1]
        assert link.state is LinkState.CONNECTING and "ur10e_shoulder_pan" in why and "missing shoulder_pan" in why
        assert "shoulder_pan -> ur10e_shoulder_pan" in why
        writer.write(Joints(Hdr(Stamp(1_700_000_001, 0), "base"), ["finger_a", "finger_b"], [0.0, 0.0], [], []))
        assert wait_until(lambda: link.stats_snapshot()["wrong_joint_count"] == 2)
    finally:
        link.close()


@dataclass
class Text(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str


def test_a_topic_of_another_message_type_is_said_not_waited_for(domain):
    """A publisher of std_msgs/String on /joint_states: a JointState reader never matches it, so the topic looked
    silent ("waiting for /joint_states"); DDS discovery tells the type, and the link's state says it."""
    dp = DomainParticipant(domain)
    writer = DataWriter(dp, Topic(dp, "rt/joint_states", Text))
    link = open_controller("ros2:///joint_states", _context())
    states = []
    link.state_changed.connect(lambda state, why: states.append((state, why)))
    link.start()
    try:
        writer.write(Text("hello"))
        assert wait_until(
            lambda: any("carries std_msgs/msg/String, not sensor_msgs/msg/JointState" in why for _, why in states),
            timeout_s=10,
        )
        assert link.state is LinkState.CONNECTING and f"joint_states on ROS domain {domain}" in states[-1][1]
    finally:
        link.close()


def test_dds_type_names_read_as_ros_names():
    from calib_core.ros2.topic_types import ros_type_name

    assert ros_type_name("sensor_msgs::msg::dds_::JointState_") == "sensor_msgs/msg/JointState"
    assert ros_type_name("my::Thing") == "my::Thing"


def test_a_renaming_is_suggested_only_when_it_is_one_to_one():
    from calib_core.ros2.joint_names import suggest_joint_names

    assert suggest_joint_names(["a_joint", "b_joint"], ["left_a_joint", "left_b_joint"]) == {
        "a_joint": "left_a_joint",
        "b_joint": "left_b_joint",
    }
    assert suggest_joint_names(["a_joint", "b_joint"], ["left_a_joint", "right_a_joint", "left_b_joint"]) is None
    assert suggest_joint_names(["a_joint"], ["finger"]) is None
