"""A simulated ros2_control arm on Cyclone DDS: what a robot's ROS 2 driver shows the network.

It publishes ``sensor_msgs/JointState`` on ``/joint_states`` (rad, m; stamped by its clock, ``time.time_ns``)
at ``rate_hz`` with ROS 2's default QoS, as ``joint_state_broadcaster`` does, and follows
``trajectory_msgs/JointTrajectory`` messages on ``/<controller>/joint_trajectory`` as
``joint_trajectory_controller``'s topic interface does: a new trajectory replaces the running one and starts
from where the joints are, its points interpolated in time; a trajectory naming other joints, a point past a
joint limit, a non-increasing ``time_from_start`` or no point at all (the controller says "Empty trajectory
received.") is rejected (and logged), leaving the arm doing what it did. It serves the controller's
``FollowJointTrajectory`` action as well (:mod:`videocal_sim.ros2_action_server`), unless ``action=False``.
It reads no truth: it is the controller, not the world.
"""

from __future__ import annotations

import sys
import threading
import time

import numpy as np


class SimulatedRos2Arm:
    """``joint_names`` (URDF order), ``per_si`` (n,) deg per rad or mm per m, limits (n,) in deg/mm,
    ``initial_deg`` (n,). ``log``: where rejections are said."""

    def __init__(
        self,
        joint_names,
        per_si,
        lower_deg,
        upper_deg,
        initial_deg,
        *,
        rate_hz: float = 100.0,
        domain: int = 0,
        controller: str = "joint_trajectory_controller",
        joint_states: str = "/joint_states",
        log=sys.stderr,
        action: bool = True,
    ):
        self.joint_names = list(joint_names)
        self.per_si = np.asarray(per_si, float)
        self.lower, self.upper = np.asarray(lower_deg, float), np.asarray(upper_deg, float)
        self.q = np.asarray(initial_deg, float).copy()
        self.rate_hz = float(rate_hz)
        self.domain = domain
        self.controller = controller
        self.joint_states = joint_states
        self.log = log
        self.published = 0
        self.trajectories = 0
        self.rejected = 0
        self.plan_number = 0
        """Counts the trajectories taken (from the topic or the action): a goal knows whether its own still runs."""
        self.action = None
        self._serve_action = action
        self._plan: tuple[float, np.ndarray, np.ndarray] | None = None  # (t0 s, times (k+1,), points (k+1, n))
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []

    def start(self) -> SimulatedRos2Arm:
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from calib_core.ros2 import messages as msg
        from calib_core.ros2.participant import participant
        from calib_core.ros2.taker import Taker
        from calib_core.ros2.wire import dds_topic, default_qos

        dp = participant(self.domain)
        self._writer = DataWriter(dp, Topic(dp, dds_topic(self.joint_states), msg.JointState), qos=default_qos(10))
        self._reader = DataReader(
            dp, Topic(dp, dds_topic(f"/{self.controller}/joint_trajectory"), msg.JointTrajectory), qos=default_qos(10)
        )
        self._taker = Taker(self._reader)
        for target, name in ((self._publish_loop, "joint_states"), (self._listen_loop, "trajectories")):
            thread = threading.Thread(target=target, name=f"sim ros2 {name}", daemon=True)
            thread.start()
            self._threads.append(thread)
        if self._serve_action:
            from videocal_sim.ros2_action_server import FollowJointTrajectoryServer

            self.action = FollowJointTrajectoryServer(self).start()
        return self

    def close(self) -> None:
        if self.action is not None:
            self.action.close()
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout=1.0)
        if self._threads and not any(thread.is_alive() for thread in self._threads):
            from calib_core.ros2.participant import delete

            self._taker.close()
            delete(self._writer)

    # --- the controller ------------------------------------------------------------------------
    def position(self, now: float) -> np.ndarray:
        with self._lock:
            plan = self._plan
            if plan is None:
                return self.q.copy()
            t0, times, points = plan
            t = now - t0
            if t >= times[-1]:
                self.q, self._plan = points[-1].copy(), None
                return self.q.copy()
            k = int(np.searchsorted(times, t, side="right")) - 1
            f = (t - times[k]) / (times[k + 1] - times[k])
            return points[k] + f * (points[k + 1] - points[k])

    def follow(self, message, now: float) -> str | None:
        """Take a trajectory (or say why not: then the arm keeps doing what it did)."""
        names = list(message.joint_names)
        if sorted(names) != sorted(self.joint_names) or len(set(names)) != len(names):
            return f"joint names {names} are not this controller's {self.joint_names}"
        if not message.points:
            return "Empty trajectory received."
        order = [names.index(n) for n in self.joint_names]
        points, times = [], []
        for i, point in enumerate(message.points):
            if len(point.positions) != len(names):
                return f"point {i} has {len(point.positions)} positions for {len(names)} joints"
            q = np.array([point.positions[j] for j in order], float) * self.per_si
            if not np.all(np.isfinite(q)) or np.any(q < self.lower - 1e-6) or np.any(q > self.upper + 1e-6):
                return f"point {i} lies outside the joint limits"
            t = point.time_from_start.seconds()
            if times and t <= times[-1] or t < 0:
                return f"point {i}: time_from_start must increase"
            points.append(q)
            times.append(t)
        current = self.position(now)
        with self._lock:
            if times[0] <= 0.0:  # a first point at 0 s: reached at once
                times[0] = 1e-3
            self._plan = (now, np.array([0.0] + times), np.array([current] + points))
            self.plan_number += 1
        return None

    def plan_done(self, now: float) -> bool:
        """The trajectory taken last has run out (the arm stands at its last point)."""
        self.position(now)
        with self._lock:
            return self._plan is None

    def plan_end(self) -> np.ndarray:
        """Where the running trajectory ends (deg, mm), or where the arm stands."""
        with self._lock:
            return self._plan[2][-1].copy() if self._plan is not None else self.q.copy()

    def hold(self, now: float) -> None:
        """Stop where the arm is (a cancelled goal: the controller holds its position)."""
        q = self.position(now)
        with self._lock:
            self.q, self._plan = q, None

    def _listen_loop(self) -> None:
        while not self._stop.is_set():
            for message in self._taker.take(10, 0.02):
                why = self.follow(message, time.monotonic())
                self.trajectories += 1
                if why is not None:
                    self.rejected += 1
                    print(f"{self.controller}: trajectory rejected: {why}", file=self.log, flush=True)

    def _publish_loop(self) -> None:
        from calib_core.ros2 import messages as msg

        period = 1.0 / self.rate_hz
        next_s = time.monotonic()
        while not self._stop.is_set():
            q_si = self.position(time.monotonic()) / self.per_si
            stamp = msg.Time.of_ns(time.time_ns())
            self._writer.write(
                msg.JointState(msg.Header(stamp, "base_link"), list(self.joint_names), [float(v) for v in q_si], [], [])
            )
            self.published += 1
            next_s += period
            delay = next_s - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            else:
                next_s = time.monotonic()  # behind: publish at once, do not burst
