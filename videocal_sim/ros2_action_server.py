"""The simulated arm's ``FollowJointTrajectory`` action server, as ros2_controllers' joint_trajectory_controller serves
it.

On Cyclone DDS with ``rmw_cyclonedds_cpp``'s service framing (:mod:`calib_core.ros2.action_types`). What the
controller does, and so this server:
- a goal whose trajectory the controller cannot follow (other joints, no point, a point past a limit, times not
  increasing) is refused; an accepted goal preempts the running one, which ends *canceled* with ``INVALID_GOAL`` and
  "Current goal cancelled due to new incoming action.";
- while a goal runs, feedback (desired, actual, error) at ``feedback_hz`` and its status on the status topic;
- the goal *succeeds* when its trajectory has run out (``SUCCESSFUL``); a cancel is accepted and the arm holds where
  it is (the goal ends *canceled*);
- a trajectory on the topic interface replaces a running goal's motion, which then ends *aborted*.
"""

from __future__ import annotations

import threading
import time

import numpy as np

from calib_core.ros2 import action_types as at


class FollowJointTrajectoryServer:
    """Serves ``/<arm.controller>/follow_joint_trajectory`` for ``arm``
    (:class:`videocal_sim.ros2_arm.SimulatedRos2Arm`)."""

    def __init__(self, arm, *, feedback_hz: float = 20.0):
        self.arm = arm
        self.name = f"/{arm.controller}/follow_joint_trajectory"
        self.feedback_hz = feedback_hz
        self.accepted = self.refused = self.cancelled = 0
        self._active: tuple[bytes, int] | None = None  # (goal id, the arm's plan number it runs)
        self._results: dict[bytes, tuple[int, int, str]] = {}  # goal id -> (status, error code, text)
        self._waiting: dict[bytes, list] = {}  # goal id -> result requests not answered yet
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> FollowJointTrajectoryServer:
        from cyclonedds.core import Policy, Qos
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from calib_core.ros2.participant import participant
        from calib_core.ros2.taker import Taker
        from calib_core.ros2.wire import default_qos, static_tf_qos

        import os

        dp = participant(self.arm.domain)
        topics = at.action_topics(self.name)
        qos = default_qos(10)
        qos = Qos(Policy.Userdata(at.client_id_user_data("serviceid", os.urandom(16))), base=qos)
        self._takers, self._replies = {}, {}
        for service, (request_type, reply_type) in at.SERVICES.items():
            self._takers[service] = Taker(
                DataReader(dp, Topic(dp, topics[f"{service}.request"], request_type), qos=qos)
            )
            self._replies[service] = DataWriter(dp, Topic(dp, topics[f"{service}.reply"], reply_type), qos=qos)
        self._feedback = DataWriter(dp, Topic(dp, topics["feedback"], at.FeedbackMessage), qos=default_qos(10))
        self._status = DataWriter(dp, Topic(dp, topics["status"], at.GoalStatusArray), qos=static_tf_qos())
        self._thread = threading.Thread(target=self._serve, name="sim ros2 follow_joint_trajectory", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        if self._thread is not None and not self._thread.is_alive():
            # a closed server is gone from the domain at once: a client must not find it and send it goals
            from calib_core.ros2.participant import delete

            for taker in self._takers.values():
                taker.close()
            delete(*self._replies.values(), self._feedback, self._status)

    # --- the services --------------------------------------------------------------------------
    def _serve(self) -> None:
        period = 1.0 / self.feedback_hz
        next_feedback = time.monotonic()
        while not self._stop.is_set():
            for request in self._takers["send_goal"].take(10, 0.01):
                self._on_goal(request)
            for request in self._takers["cancel_goal"].take(10, 0.0):
                self._on_cancel(request)
            for request in self._takers["get_result"].take(10, 0.0):
                self._on_get_result(request)
            now = time.monotonic()
            self._watch_active(now)
            if self._active is not None and now >= next_feedback:
                self._send_feedback(now)
                next_feedback = now + period

    def _on_goal(self, request) -> None:
        goal_id = bytes(request.goal_id.uuid)
        why = self.arm.follow(request.goal.trajectory, time.monotonic())
        accepted = why is None
        if accepted:
            self.accepted += 1
            self._end_active(at.CANCELED, -1, "Current goal cancelled due to new incoming action.")
            with self._lock:
                self._active = (goal_id, self.arm.plan_number)
        else:
            self.refused += 1
            print(f"{self.arm.controller}: goal refused: {why}", file=self.arm.log, flush=True)
        stamp = at.Time.of_ns(time.time_ns())
        self._replies["send_goal"].write(at.SendGoalResponse(header=request.header, accepted=accepted, stamp=stamp))
        self._publish_status()

    def _on_cancel(self, request) -> None:
        goal_id = bytes(request.goal_info.goal_id.uuid)
        active = self._active
        if active is not None and active[0] == goal_id:
            self.arm.hold(time.monotonic())
            self.cancelled += 1
            self._end_active(at.CANCELED, 0, "")
            code, canceling = at.CANCEL_ERROR_NONE, [request.goal_info]
        elif goal_id in self._results:
            code, canceling = at.CANCEL_ERROR_GOAL_TERMINATED, []
        else:
            code, canceling = at.CANCEL_ERROR_UNKNOWN_GOAL_ID, []
        self._replies["cancel_goal"].write(
            at.CancelGoalResponse(header=request.header, return_code=code, goals_canceling=canceling)
        )

    def _on_get_result(self, request) -> None:
        goal_id = bytes(request.goal_id.uuid)
        with self._lock:
            ended = self._results.get(goal_id)
            if ended is None:
                self._waiting.setdefault(goal_id, []).append(request.header)
                return
        self._answer(request.header, ended)

    def _answer(self, header, ended: tuple[int, int, str]) -> None:
        status, code, text = ended
        self._replies["get_result"].write(
            at.GetResultResponse(header=header, status=status, result=at.FollowJointTrajectoryResult(code, text))
        )

    # --- the running goal ----------------------------------------------------------------------
    def _watch_active(self, now: float) -> None:
        active = self._active
        if active is None:
            return
        if self.arm.plan_number != active[1]:
            self._end_active(at.ABORTED, -1, "the trajectory was replaced by one on the controller's topic")
        elif self.arm.plan_done(now):
            self._end_active(at.SUCCEEDED, 0, "")

    def _end_active(self, status: int, code: int, text: str) -> None:
        with self._lock:
            active, self._active = self._active, None
            if active is None:
                return
            self._results[active[0]] = (status, code, text)
            headers = self._waiting.pop(active[0], [])
        for header in headers:
            self._answer(header, (status, code, text))
        self._publish_status(ended=(active[0], status))

    def _publish_status(self, ended: tuple[bytes, int] | None = None) -> None:
        listed = []
        active = self._active
        if active is not None:
            listed.append(at.GoalStatus(at.GoalInfo(at.UUID(list(active[0]))), at.EXECUTING))
        if ended is not None:
            listed.append(at.GoalStatus(at.GoalInfo(at.UUID(list(ended[0]))), ended[1]))
        self._status.write(at.GoalStatusArray(listed))

    def _send_feedback(self, now: float) -> None:
        from calib_core.ros2 import messages as msg

        active = self._active
        actual = self.arm.position(now)
        desired = self.arm.plan_end()
        si = self.arm.per_si
        point = lambda q: msg.JointTrajectoryPoint(positions=[float(v) for v in np.asarray(q) / si])  # noqa: E731
        feedback = at.FollowJointTrajectoryFeedback(
            header=msg.Header(msg.Time.of_ns(time.time_ns())),
            joint_names=list(self.arm.joint_names),
            desired=point(desired),
            actual=point(actual),
            error=point(desired - actual),
        )
        if active is not None:
            self._feedback.write(at.FeedbackMessage(at.UUID(list(active[0])), feedback))
