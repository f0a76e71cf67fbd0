"""The FollowJointTrajectory action: its framing on the wire as rmw_cyclonedds_cpp puts it, the client against the
simulated joint_trajectory_controller's server, and what the controller says reaching the operator."""

import math
import struct
import time

import numpy as np
import pytest

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState, MoveError
from calib_core.ros2 import action_types as at
from calib_core.ros2 import messages as msg
from calib_core.ros2.action_client import FollowJointTrajectoryClient
from videocal_sim.ros2_arm import SimulatedRos2Arm
from tests.waiting import wait_until

NAMES = ("j1", "j2", "j3")
ACTION = "/arm_controller/follow_joint_trajectory"


@pytest.fixture
def arm(domain):
    arm = SimulatedRos2Arm(
        NAMES,
        [180 / math.pi] * 3,
        [-170.0] * 3,
        [170.0] * 3,
        [0.0, 10.0, 20.0],
        rate_hz=200.0,
        domain=domain,
        controller="arm_controller",
    ).start()
    yield arm
    arm.close()


def _goal(positions_deg, seconds=0.5, names=NAMES):
    point = msg.JointTrajectoryPoint(
        positions=[math.radians(v) for v in positions_deg], time_from_start=msg.Duration.of_s(seconds)
    )
    return at.FollowJointTrajectoryGoal(trajectory=msg.JointTrajectory(msg.Header(), list(names), [point]))


def _events(client, want, timeout_s=5.0):
    got = []
    wait_until(lambda: got.extend(client.poll(0.01)) or len(got) >= want, timeout_s)
    return got


def test_a_request_is_rmw_cyclonedds_header_then_the_request():
    """``cdds_request_header_t`` (uint64 client id, int64 sequence number) first, then the ROS request's fields, in
    plain little-endian CDR after the 4-byte encapsulation header: read back by hand."""
    goal_id = bytes(range(16))
    data = at.GetResultRequest(at.RequestHeader(0x0102030405060708, 42), at.UUID(list(goal_id))).serialize()
    assert data[:2] == b"\x00\x01"  # CDR, little-endian
    guid, seq = struct.unpack_from("<Qq", data, 4)
    assert (guid, seq) == (0x0102030405060708, 42)
    assert data[20:36] == goal_id and len(data) == 36
    reply = at.SendGoalResponse(at.RequestHeader(7, 3), True, msg.Time(12, 34)).serialize()
    assert struct.unpack_from("<Qq?", reply, 4) == (7, 3, True)
    assert struct.unpack_from("<iI", reply, 24) == (12, 34)  # the stamp 4-aligned after the bool


def test_the_topic_names_and_user_data_are_rcl_action_s_and_rmw_cyclonedds_s():
    topics = at.action_topics(ACTION)
    assert topics["send_goal.request"] == "rq/arm_controller/follow_joint_trajectory/_action/send_goalRequest"
    assert topics["get_result.reply"] == "rr/arm_controller/follow_joint_trajectory/_action/get_resultReply"
    assert topics["status"] == "rt/arm_controller/follow_joint_trajectory/_action/status"
    # csid_to_string: hex, dot-separated, the first byte set in a field of two (space-filled)
    assert at.client_id_user_data("clientid", bytes([5, 0x7E] + [0] * 14)) == b"clientid= 5.7e" + b".0" * 14 + b";"


def test_a_goal_is_accepted_runs_and_succeeds_and_a_bad_one_is_refused(arm):
    client = FollowJointTrajectoryClient(arm.domain, ACTION)
    assert wait_until(client.server_ready)
    good = client.send_goal(_goal([5.0, 15.0, 25.0], 0.3))
    events = _events(client, 2)
    assert [(e.kind, e.goal) for e in events] == [("accepted", good), ("ended", good)]
    assert events[1].status == at.SUCCEEDED and events[1].error_code == 0
    assert np.allclose(arm.position(time.monotonic()), [5.0, 15.0, 25.0])
    bad = client.send_goal(_goal([5.0, 15.0, 25.0], names=("j1", "j2", "elbow")))
    assert [(e.kind, e.goal) for e in _events(client, 1)] == [("refused", bad)]


def test_a_new_goal_preempts_the_running_one_as_the_controller_does(arm):
    client = FollowJointTrajectoryClient(arm.domain, ACTION)
    assert wait_until(client.server_ready)
    first = client.send_goal(_goal([90.0, 10.0, 20.0], 5.0))
    assert _events(client, 1)[0].kind == "accepted"
    second = client.send_goal(_goal([0.0, 10.0, 20.0], 0.2))
    events = _events(client, 4)
    ended = {e.goal: e for e in events if e.kind == "ended"}
    assert ended[first].status == at.CANCELED and ended[first].error_code == -1
    assert ended[first].error_string == "Current goal cancelled due to new incoming action."
    assert ended[second].status == at.SUCCEEDED


def test_replies_to_another_client_are_not_taken_as_ours(arm):
    mine, theirs = FollowJointTrajectoryClient(arm.domain, ACTION), FollowJointTrajectoryClient(arm.domain, ACTION)
    assert wait_until(lambda: mine.server_ready() and theirs.server_ready())
    goal = theirs.send_goal(_goal([1.0, 10.0, 20.0], 0.2))
    assert {e.goal for e in _events(theirs, 2)} == {goal}
    assert mine.poll(0.2) == []


def test_cancel_holds_the_arm_and_an_unknown_goal_is_said(arm):
    client = FollowJointTrajectoryClient(arm.domain, ACTION)
    assert wait_until(client.server_ready)
    goal = client.send_goal(_goal([120.0, 10.0, 20.0], 6.0))
    assert _events(client, 1)[0].kind == "accepted"
    assert wait_until(lambda: arm.position(time.monotonic())[0] > 5.0)
    client.cancel(goal)
    events = _events(client, 2)
    assert {(e.kind, e.status) for e in events} == {("cancel", at.CANCEL_ERROR_NONE), ("ended", at.CANCELED)}
    held = arm.position(time.monotonic())[0]
    assert 5.0 < held < 60.0 and arm.plan_done(time.monotonic())
    client.cancel(b"\x01" * 16)
    assert [(e.kind, e.status) for e in _events(client, 1)] == [("cancel", at.CANCEL_ERROR_UNKNOWN_GOAL_ID)]


def test_a_goal_the_controller_aborts_ends_the_move_with_its_reason(arm):
    """Someone else's trajectory on the controller's topic replaces the running goal's motion: the controller aborts
    the goal, and the operator's move ends with that, not at its deadline."""
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic

    from calib_core.ros2.participant import participant
    from calib_core.ros2.wire import dds_topic, default_qos

    link = open_controller(
        "ros2:///joint_states",
        ControllerContext(
            NAMES, ("deg",) * 3, JointMap.identity(3), 100.0, {"controller": "arm_controller", "speed_deg_s": 10}
        ),
    ).start()
    try:
        assert wait_until(lambda: link.state is LinkState.UP and link._goals.client.server_ready())
        handle = link.move_joints([100.0, 10.0, 20.0], timeout_s=60)
        assert wait_until(lambda: arm.action.accepted >= 1)
        dp = participant(arm.domain)
        other = DataWriter(
            dp, Topic(dp, dds_topic("/arm_controller/joint_trajectory"), msg.JointTrajectory), qos=default_qos(1)
        )
        assert wait_until(lambda: other.get_publication_matched_status().current_count > 0)
        other.write(_goal([0.0, 10.0, 20.0], 0.2).trajectory)
        with pytest.raises(MoveError, match="the controller aborted the move"):
            handle.wait(5)
    finally:
        link.close()


def test_insisting_on_the_action_without_a_server_is_not_sent(domain):
    arm = SimulatedRos2Arm(
        NAMES,
        [180 / math.pi] * 3,
        [-170.0] * 3,
        [170.0] * 3,
        [0.0] * 3,
        domain=domain,
        controller="arm_controller",
        action=False,
    ).start()
    link = open_controller(
        "ros2:///joint_states",
        ControllerContext(
            NAMES, ("deg",) * 3, JointMap.identity(3), 100.0, {"controller": "arm_controller", "interface": "action"}
        ),
    ).start()
    try:
        assert wait_until(lambda: link.state is LinkState.UP)
        handle = link.move_joints([1.0, 0.0, 0.0])
        assert not handle.sent and f"no FollowJointTrajectory action server at {ACTION}" in str(handle.error)
    finally:
        link.close()
        arm.close()


def test_a_closed_arm_s_action_server_is_gone_from_the_domain_at_once(arm, domain):
    # DDS entities left to Python's collector stay discoverable: a later client on the domain found the action server
    # of an arm closed long before and sent it its goals
    client = FollowJointTrajectoryClient(domain, ACTION)
    try:
        assert wait_until(client.server_ready)
        arm.close()
        assert wait_until(lambda: not client.server_ready())
    finally:
        client.close()


def test_a_closed_link_s_action_client_and_reader_are_gone_from_the_domain_at_once(arm):
    link = open_controller(
        "ros2:///joint_states",
        ControllerContext(
            NAMES, ("deg",) * 3, JointMap.identity(3), 100.0, {"controller": "arm_controller", "interface": "action"}
        ),
    ).start()
    requests = arm.action._takers["send_goal"].reader
    try:
        assert wait_until(lambda: link.state is LinkState.UP)
        assert wait_until(lambda: requests.get_subscription_matched_status().current_count == 1)
        assert arm._writer.get_publication_matched_status().current_count == 1  # the link's joint_states reader
    finally:
        link.close()
    assert wait_until(lambda: requests.get_subscription_matched_status().current_count == 0)
    assert wait_until(lambda: arm._writer.get_publication_matched_status().current_count == 0)
