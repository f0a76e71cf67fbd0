"""``control_msgs/action/FollowJointTrajectory`` as DDS carries it, with ROS 2's action plumbing.

A ROS 2 action is three services and two topics under ``<action>/_action/`` (rcl_action): ``send_goal``,
``cancel_goal`` and ``get_result``; ``feedback`` and ``status``. A service is a request topic ``rq/<service>Request``
and a reply topic ``rr/<service>Reply`` whose types (``pkg::action::dds_::Action_SendGoal_Request_``, ...) are the
request or response with ``rmw_cyclonedds_cpp``'s request header in front: the client's 64-bit id and the request's
sequence number, echoed in the reply (``cdds_request_header_t``, rmw_cyclonedds_cpp/src/serdata.hpp).

The goal, result and feedback are control_msgs' of ROS 2 Humble and Jazzy (control_msgs 4 and 5: the goal carries
the multi-DOF trajectory and the per-component tolerances). Later releases add fields in the middle of the feedback,
which is why videocal reads the arm from its joint states, never from the feedback.
"""

# No ``from __future__ import annotations``: cyclonedds reads these annotations as types.
from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float64, int8, int32, int64, sequence, uint8, uint16, uint64

from calib_core.ros2.messages import Duration, Header, JointTrajectory, JointTrajectoryPoint, Time, Transform, Vector3

ACCEPTED, EXECUTING, CANCELING, SUCCEEDED, CANCELED, ABORTED = 1, 2, 3, 4, 5, 6
"""``action_msgs/GoalStatus`` values."""
STATUS_NAMES = {
    0: "unknown",
    ACCEPTED: "accepted",
    EXECUTING: "executing",
    CANCELING: "canceling",
    SUCCEEDED: "succeeded",
    CANCELED: "canceled",
    ABORTED: "aborted",
}
ERROR_NAMES = {
    0: "SUCCESSFUL",
    -1: "INVALID_GOAL",
    -2: "INVALID_JOINTS",
    -3: "OLD_HEADER_TIMESTAMP",
    -4: "PATH_TOLERANCE_VIOLATED",
    -5: "GOAL_TOLERANCE_VIOLATED",
}
"""``FollowJointTrajectory`` result codes."""
CANCEL_ERROR_NONE, CANCEL_ERROR_REJECTED, CANCEL_ERROR_UNKNOWN_GOAL_ID, CANCEL_ERROR_GOAL_TERMINATED = 0, 1, 2, 3


@dataclass
class RequestHeader(IdlStruct, typename="videocal::cdds_request_header"):
    """``rmw_cyclonedds_cpp``'s header before every request and reply: who asked (``guid``) and which request
    (``seq``)."""

    guid: uint64 = 0
    seq: int64 = 0


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: array[uint8, 16] = field(default_factory=lambda: [0] * 16)


@dataclass
class GoalInfo(IdlStruct, typename="action_msgs::msg::dds_::GoalInfo_"):
    goal_id: UUID = field(default_factory=UUID)
    stamp: Time = field(default_factory=Time)


@dataclass
class GoalStatus(IdlStruct, typename="action_msgs::msg::dds_::GoalStatus_"):
    goal_info: GoalInfo = field(default_factory=GoalInfo)
    status: int8 = 0


@dataclass
class GoalStatusArray(IdlStruct, typename="action_msgs::msg::dds_::GoalStatusArray_"):
    status_list: sequence[GoalStatus] = field(default_factory=list)


@dataclass
class CancelGoalRequest(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Request_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    goal_info: GoalInfo = field(default_factory=GoalInfo)


@dataclass
class CancelGoalResponse(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Response_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    return_code: int8 = 0
    goals_canceling: sequence[GoalInfo] = field(default_factory=list)


@dataclass
class JointTolerance(IdlStruct, typename="control_msgs::msg::dds_::JointTolerance_"):
    name: str = ""
    position: float64 = 0.0
    velocity: float64 = 0.0
    acceleration: float64 = 0.0


@dataclass
class JointComponentTolerance(IdlStruct, typename="control_msgs::msg::dds_::JointComponentTolerance_"):
    joint_name: str = ""
    component: uint16 = 0
    position: float64 = 0.0
    velocity: float64 = 0.0
    acceleration: float64 = 0.0


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class MultiDOFJointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectoryPoint_"):
    transforms: sequence[Transform] = field(default_factory=list)
    velocities: sequence[Twist] = field(default_factory=list)
    accelerations: sequence[Twist] = field(default_factory=list)
    time_from_start: Duration = field(default_factory=Duration)


@dataclass
class MultiDOFJointTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectory_"):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    points: sequence[MultiDOFJointTrajectoryPoint] = field(default_factory=list)


@dataclass
class FollowJointTrajectoryGoal(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Goal_"):
    trajectory: JointTrajectory = field(default_factory=JointTrajectory)
    multi_dof_trajectory: MultiDOFJointTrajectory = field(default_factory=MultiDOFJointTrajectory)
    path_tolerance: sequence[JointTolerance] = field(default_factory=list)
    component_path_tolerance: sequence[JointComponentTolerance] = field(default_factory=list)
    goal_tolerance: sequence[JointTolerance] = field(default_factory=list)
    component_goal_tolerance: sequence[JointComponentTolerance] = field(default_factory=list)
    goal_time_tolerance: Duration = field(default_factory=Duration)


@dataclass
class FollowJointTrajectoryResult(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Result_"):
    error_code: int32 = 0
    error_string: str = ""


@dataclass
class FollowJointTrajectoryFeedback(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Feedback_"):
    header: Header = field(default_factory=Header)
    joint_names: sequence[str] = field(default_factory=list)
    desired: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    actual: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    error: JointTrajectoryPoint = field(default_factory=JointTrajectoryPoint)
    multi_dof_joint_names: sequence[str] = field(default_factory=list)
    multi_dof_desired: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    multi_dof_actual: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)
    multi_dof_error: MultiDOFJointTrajectoryPoint = field(default_factory=MultiDOFJointTrajectoryPoint)


@dataclass
class SendGoalRequest(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Request_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    goal_id: UUID = field(default_factory=UUID)
    goal: FollowJointTrajectoryGoal = field(default_factory=FollowJointTrajectoryGoal)


@dataclass
class SendGoalResponse(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Response_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    accepted: bool = False
    stamp: Time = field(default_factory=Time)


@dataclass
class GetResultRequest(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Request_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    goal_id: UUID = field(default_factory=UUID)


@dataclass
class GetResultResponse(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Response_"):
    header: RequestHeader = field(default_factory=RequestHeader)
    status: int8 = 0
    result: FollowJointTrajectoryResult = field(default_factory=FollowJointTrajectoryResult)


@dataclass
class FeedbackMessage(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_FeedbackMessage_"):
    goal_id: UUID = field(default_factory=UUID)
    feedback: FollowJointTrajectoryFeedback = field(default_factory=FollowJointTrajectoryFeedback)


SERVICES = {
    "send_goal": (SendGoalRequest, SendGoalResponse),
    "cancel_goal": (CancelGoalRequest, CancelGoalResponse),
    "get_result": (GetResultRequest, GetResultResponse),
}
"""Each of an action's services: (request type, reply type), both with the request header."""


def action_topics(action: str) -> dict[str, str]:
    """The DDS topic names of action ``/ns/name``: ``send_goal``, ``cancel_goal`` and ``get_result`` requests and
    replies (``<service>.request``, ``<service>.reply``), ``feedback`` and ``status``."""
    base = action.strip("/") + "/_action/"
    topics = {}
    for service in SERVICES:
        topics[f"{service}.request"] = f"rq/{base}{service}Request"
        topics[f"{service}.reply"] = f"rr/{base}{service}Reply"
    topics["feedback"] = f"rt/{base}feedback"
    topics["status"] = f"rt/{base}status"
    return topics


def client_id_user_data(role: str, ident: bytes) -> bytes:
    """The user data rmw_cyclonedds_cpp puts on a client's (``clientid``) or service's (``serviceid``) reader and
    writer, so the other side pairs them: ``clientid=<16 bytes in hex, dot-separated>;`` (the first padded to two
    characters with a space, as its ``std::setw(2)`` does)."""
    return (f"{role}=" + f"{ident[0]:>2x}" + "".join(f".{b:x}" for b in ident[1:]) + ";").encode()
