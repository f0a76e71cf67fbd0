"""A ``FollowJointTrajectory`` action client on Cyclone DDS, as ``rclcpp``/``rclpy`` with ``rmw_cyclonedds_cpp`` is one.

Goals are sent, cancelled and their results asked for through the action's three services; nothing here blocks: the
caller's thread calls :meth:`poll` and gets what came back as :class:`ActionEvent` s (a goal accepted or refused, a
goal's end with its status and result, a cancel's answer). Like rclpy's client, a result is asked for as soon as a
goal is accepted. Requests carry this client's id (its request writer's instance handle, as ``rmw_cyclonedds_cpp``
uses) and a sequence number; replies for other clients are left alone.
"""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass

from calib_core.ros2 import action_types as at


@dataclass(frozen=True)
class ActionEvent:
    """``kind``: ``"accepted"``, ``"refused"``, ``"ended"`` (``status``, ``error_code``, ``error_string``) or
    ``"cancel"`` (``status``: the cancel's return code); ``goal``: the goal's id (16 bytes)."""

    kind: str
    goal: bytes
    status: int = 0
    error_code: int = 0
    error_string: str = ""


class FollowJointTrajectoryClient:
    """The client of action ``name`` (``/joint_trajectory_controller/follow_joint_trajectory``) on ``domain``."""

    def __init__(self, domain: int, name: str):
        from cyclonedds.core import Policy, Qos
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from calib_core.ros2.participant import participant
        from calib_core.ros2.taker import Taker
        from calib_core.ros2.wire import default_qos

        self.name = name
        dp = participant(domain)
        topics = at.action_topics(name)
        qos = default_qos(10)
        qos = Qos(Policy.Userdata(at.client_id_user_data("clientid", os.urandom(16))), base=qos)
        self._writers, self._takers, self._readers = {}, {}, {}
        for service, (request_type, reply_type) in at.SERVICES.items():
            self._writers[service] = DataWriter(dp, Topic(dp, topics[f"{service}.request"], request_type), qos=qos)
            self._readers[service] = DataReader(dp, Topic(dp, topics[f"{service}.reply"], reply_type), qos=qos)
            self._takers[service] = Taker(self._readers[service])
        self._id = int(self._writers["send_goal"].instance_handle) & 0xFFFF_FFFF_FFFF_FFFF  # uint64 on the wire
        self._seq = itertools.count(1)
        self._pending: dict[tuple[str, int], bytes] = {}  # (service, seq) -> goal id

    def close(self) -> None:
        """Delete the client's readers and writers: a server no longer sees it."""
        from calib_core.ros2.participant import delete

        for taker in self._takers.values():
            taker.close()
        delete(*self._writers.values())

    def server_ready(self) -> bool:
        """Every service of the action has a server that reads our requests and writes to our reply readers."""
        return all(
            self._writers[s].get_publication_matched_status().current_count > 0
            and self._readers[s].get_subscription_matched_status().current_count > 0
            for s in at.SERVICES
        )

    def send_goal(self, goal: at.FollowJointTrajectoryGoal) -> bytes:
        """Send ``goal``; its id (16 random bytes) is returned, its acceptance comes through :meth:`poll`."""
        goal_id = os.urandom(16)
        self._request("send_goal", goal_id, goal_id=at.UUID(list(goal_id)), goal=goal)
        return goal_id

    def cancel(self, goal_id: bytes) -> None:
        """Ask the server to cancel ``goal_id`` (a trajectory controller then holds where the arm is)."""
        self._request("cancel_goal", goal_id, goal_info=at.GoalInfo(goal_id=at.UUID(list(goal_id))))

    def _request(self, service: str, for_goal: bytes, **fields) -> None:
        seq = next(self._seq)
        self._pending[(service, seq)] = for_goal
        request_type = at.SERVICES[service][0]
        self._writers[service].write(request_type(header=at.RequestHeader(self._id, seq), **fields))

    def poll(self, timeout_s: float = 0.0) -> list[ActionEvent]:
        """What came back since the last call (waiting at most ``timeout_s`` for the first reply of each service)."""
        events = []
        for service, taker in self._takers.items():
            for reply in taker.take(20, timeout_s):
                goal_id = (
                    self._pending.pop((service, int(reply.header.seq)), None)
                    if int(reply.header.guid) == self._id
                    else None
                )
                if goal_id is None:
                    continue  # another client's reply
                if service == "send_goal":
                    events.append(ActionEvent("accepted" if reply.accepted else "refused", goal_id))
                    if reply.accepted:
                        self._request("get_result", goal_id, goal_id=at.UUID(list(goal_id)))
                elif service == "get_result":
                    events.append(
                        ActionEvent(
                            "ended",
                            goal_id,
                            int(reply.status),
                            int(reply.result.error_code),
                            str(reply.result.error_string),
                        )
                    )
                else:
                    events.append(ActionEvent("cancel", goal_id, int(reply.return_code)))
        return events
