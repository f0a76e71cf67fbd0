"""The ROS 2 controller connector: joints from ``sensor_msgs/JointState``, moves through ros2_control's
``joint_trajectory_controller``, on Cyclone DDS.

URL ``ros2:///joint_states`` (the joint states topic; ``?controller=NAME&domain=N&qos=sensor`` or the
``site:`` section's ``controller_options`` with the same names). Joints are taken by URDF name (the cell's
robot), so the connector's axes are the model's (:meth:`JointMap.identity`); ROS's rad and m become deg and
mm. A sample's time is its header stamp (the controller's clock), never its arrival.

Moves: through the controller's ``FollowJointTrajectory`` action (``/<controller>/follow_joint_trajectory``) when it
serves one, else as ``trajectory_msgs/JointTrajectory`` on ``/<controller>/joint_trajectory`` (its topic interface;
``?interface=action`` or ``topic`` insists on one), streamed either way as a dead-man: the move is a straight line in
joint space at ``speed_deg_s``, and the controller is only ever given the next ``horizon_s`` of it (one point,
``horizon_s`` of motion beyond where the joint states put the arm), renewed every third of that. Each message
replaces the last (what the controller does with a new trajectory), so while they arrive the arm moves without
a pause; when they stop (the workstation gone, the network cut, the joint states stale) the arm stops within
``horizon_s`` of motion, on the line. A one-point trajectory to the target did run on to it whatever became of
the workstation. The commanded point only moves forward along the line, so a late joint state never turns the
arm back. Through the action each renewal is a goal that preempts the last
(:mod:`calib_core.ros2.trajectory_goals`): a refused or aborted goal ends the move with the controller's reason, and
Stop cancels the running goal. A move is *done* when the joint states stand within ``done_tolerance_deg`` of the target;
*refused* at
once when no trajectory controller subscribes to the topic; *stopped* by Stop, which sends a trajectory that
holds the current position. No joint states for ``stale_after_s``: the link is ``stale``, the robot's pose
unknown, and a move under way ends with that error (it is not renewed: the arm stops within its horizon).

A far link (a satellite's seconds): the joint states' delay is measured from their stamps (:attr:`delay_s`, clocks in
step as ROS 2 assumes), and what waits on the link follows it. The horizon given is ``horizon_s`` plus the round trip
(twice the delay) and its spread, so the arm does not stop at each point waiting for the next, and after a lost
link it stops within that much motion, still on the line; ``stale_after_s`` is lengthened by the delay's spread,
so a late burst of samples is not taken for a lost robot. Each point's time is counted from where the last joint
states put the arm, which is behind where it is: the arm never goes faster than ``speed_deg_s``, and across a
round trip of seconds it goes about half as fast.
"""

from __future__ import annotations

import itertools
import threading
import time
from urllib.parse import parse_qs

import numpy as np

from calib_core.connectors.urls import split_url
from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.options import number_option
from calib_core.connectors.events import ConnectorEvents, SingleMove
from calib_core.link.arrival_delay import ArrivalDelay
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkError, LinkState, LinkStats, MoveError, MoveHandle, TimedSample
from calib_core.connectors.link_types import JointSample
from calib_core.link.sample_order import SampleOrder
from calib_core.ros2.joint_names import foreign_joints_text
from calib_core.ros2.joint_units import user_per_si

DEFAULT_CONTROLLER = "joint_trajectory_controller"
_OPTIONS = {
    "controller",
    "domain",
    "qos",
    "interface",
    "speed_deg_s",
    "done_tolerance_deg",
    "stale_after_s",
    "horizon_s",
}
INTERFACES = ("auto", "action", "topic")


def _options(url: str, context: ControllerContext) -> tuple[str, dict]:
    parts = split_url(url, LinkError)
    if parts.netloc:
        raise LinkError(
            f"{url!r}: a ros2 URL has no host (ros2:///joint_states); the domain is ROS_DOMAIN_ID or ?domain=N"
        )
    topic = parts.path or "/joint_states"
    options = dict(context.options or {})
    for key, values in parse_qs(parts.query, keep_blank_values=True).items():
        options[key] = values[-1]
    unknown = set(options) - _OPTIONS
    if unknown:
        raise LinkError(
            f"{url!r}: unknown option(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_OPTIONS))}"
        )
    return topic, options


TYPE_CHECK_S = 1.0
"""While nothing has come, how often the topic's publishers' types are looked at (s)."""


class Ros2TrajectoryController(ConnectorEvents):
    """See the module. ``context.joint_names`` are the joints looked for in each JointState message.
    (``auth_changed`` is never emitted: ROS 2 has no session.)

    Its public members are the connector protocol (start, close, latest, delay_s, stats_snapshot, move_joints, stop;
    publish_static_transforms) and the configuration read from its URL (topics, action, domain, speeds, tolerances),
    kept public for the status line and the tests to read what it was told."""

    publishes_transforms = True

    def __init__(self, url: str, context: ControllerContext):
        from calib_core.ros2.wire import domain_id, dds_topic

        if not context.n_joints:
            raise LinkError(f"{url}: a ROS 2 controller is read by joint names: give the cell (--workcell)")
        self.url = url
        topic, options = _options(url, context)
        self.controller = str(options.get("controller", DEFAULT_CONTROLLER)).strip("/")
        self.domain = domain_id(options.get("domain"))
        self._qos_name = str(options.get("qos", "default"))
        if self._qos_name not in ("default", "sensor"):
            raise LinkError(f"ros2 option qos: 'default' or 'sensor', got {self._qos_name!r}")
        self.interface = str(options.get("interface", "auto"))
        if self.interface not in INTERFACES:
            raise LinkError(f"ros2 option interface: one of {', '.join(INTERFACES)}, got {self.interface!r}")
        self.speed_deg_s = number_option(options, "speed_deg_s", 20.0, 0.1, 1000.0, "ros2")
        self.done_tolerance_deg = number_option(options, "done_tolerance_deg", 0.05, 1e-4, 10.0, "ros2")
        self.stale_after_s = number_option(
            options, "stale_after_s", max(5.0 / context.rate_hz, 0.5), 0.05, 60.0, "ros2"
        )
        self.horizon_s = number_option(options, "horizon_s", 0.5, 0.1, 30.0, "ros2")
        self.joint_states_topic = dds_topic(topic)
        self.trajectory_topic = dds_topic(f"/{self.controller}/joint_trajectory")
        self.action_name = f"/{self.controller}/follow_joint_trajectory"
        self._goals = None  # the action's goals (GoalStream), when the controller serves it
        self._through_action = False  # the move under way goes through the action
        self.joint_names = list(context.joint_names)
        self.n_joints = context.n_joints
        self.joint_map = JointMap.identity(self.n_joints)
        self._per_si = user_per_si(context.joint_units)
        self.stats = LinkStats()
        self._lock = threading.Lock()
        self._moves = SingleMove()
        self._order = SampleOrder(self.stats)
        self._seq = itertools.count()
        self._ids = itertools.count(1)
        self._latest: TimedSample | None = None
        self._last_sample_s: float | None = None
        self._arrival = ArrivalDelay()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._reader = self._writer = None
        self._tf = None
        # the move being streamed: (start (n,), target (n,), duration s), the commanded fraction of it, when renewed
        self._path: tuple[np.ndarray, np.ndarray, float] | None = None
        self._s_commanded = 0.0
        self._renewed_s = 0.0
        self._path_lock = threading.Lock()

    # --- life cycle ----------------------------------------------------------------------------
    def start(self) -> Ros2TrajectoryController:
        from cyclonedds.pub import DataWriter
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from calib_core.ros2 import messages as msg
        from calib_core.ros2.participant import participant
        from calib_core.ros2.taker import Taker
        from calib_core.ros2.topic_types import TopicTypes
        from calib_core.ros2.wire import default_qos, sensor_qos

        if self._thread is not None:
            return self
        dp = participant(self.domain)
        reader_qos = sensor_qos(100) if self._qos_name == "sensor" else default_qos(100)
        self._reader = DataReader(dp, Topic(dp, self.joint_states_topic, msg.JointState), qos=reader_qos)
        self._writer = DataWriter(dp, Topic(dp, self.trajectory_topic, msg.JointTrajectory), qos=default_qos(1))
        if self.interface != "topic":
            from calib_core.ros2.action_client import FollowJointTrajectoryClient
            from calib_core.ros2.trajectory_goals import GoalStream

            self._goals = GoalStream(FollowJointTrajectoryClient(self.domain, self.action_name))
        self._taker = Taker(self._reader)
        self._types = TopicTypes(dp)
        self._started_s = self._types_checked_s = time.monotonic()
        self._set_state(LinkState.CONNECTING, f"waiting for {self.joint_states_topic[2:]} on ROS domain {self.domain}")
        self._thread = threading.Thread(target=self._run, name=f"ros2 {self.url}", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        if self._moves.current is not None and not self._moves.current.finished:
            self.stop()
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        self._set_state(LinkState.CLOSED, "closed by the caller")
        self._moves.finish(MoveError("the link was closed"))
        if self._thread is not None and not self._thread.is_alive():
            # (gone from the domain now: a client left to the collector was found by the next link on it)
            from calib_core.ros2.participant import delete

            self._taker.close()
            self._types.close()
            delete(self._writer)
            if self._goals is not None:
                self._goals.client.close()

    @property
    def latest(self) -> TimedSample | None:
        return self._latest

    @property
    def delay_s(self) -> float | None:
        """The joint states' one-way delay (s): arrival minus header stamp, the median of the recent ones."""
        return self._arrival.one_way_s()

    @property
    def horizon_now_s(self) -> float:
        """How much of a move's motion the controller is given beyond the measured joints (s): ``horizon_s``, plus
        the round trip and its spread on a far link."""
        return self.horizon_s + 2.0 * (self._arrival.one_way_s() or 0.0) + self._arrival.spread_s

    def stats_snapshot(self) -> dict[str, int]:
        with self._lock:
            return self.stats.as_dict()

    # --- commands ------------------------------------------------------------------------------
    def move_joints(self, joints_deg, *, timeout_s: float = 60.0) -> MoveHandle:
        q = np.array([float(v) for v in joints_deg])
        if len(q) != self.n_joints or not np.all(np.abs(q) < 1e6):
            raise ValueError(f"a move needs {self.n_joints} finite joint values, got {list(q)}")
        handle = MoveHandle(f"ros2.{next(self._ids)}", tuple(q), time.monotonic() + timeout_s)
        latest = self._latest
        reason = self._why_not_sendable(latest)
        if reason is not None:
            handle.sent = False
            handle._finish(MoveError(f"move {handle.id}: not sent: {reason}"))
            return handle
        self._through_action = self._goals is not None and self._goals.client.server_ready()
        start = np.asarray(latest.joints_deg, dtype=float)
        duration_s = max(float(np.max(np.abs(q - start))) / self.speed_deg_s, 0.5)
        self._moves.begin(handle)
        with self._path_lock:
            self._path, self._s_commanded = (start, q, duration_s), 0.0
            self._renew(time.monotonic())
        handle.acked = True  # reliable delivery; a goal the controller refuses ends the move when its answer comes
        return handle

    def stop(self) -> bool:
        """Hold where the joints stand now: a one-point trajectory at the current position."""
        latest = self._latest
        if latest is None or self._writer is None or self._stop.is_set():
            return False
        with self._path_lock:
            self._path = None
        if not (self._through_action and self._goals.cancel()):
            self._publish(np.asarray(latest.joints_deg), 0.1)
        self._moves.finish(MoveError("ERR,STOPPED: stopped by the operator"))
        return True

    def publish_static_transforms(self, transforms: list[tuple[str, str, np.ndarray]]) -> None:
        """``(parent, child, child2parent_mm)`` on ``/tf_static`` (the measured camera mounting, corrected targets)."""
        if self._tf is None:
            from calib_core.ros2.tf_static import StaticTransformBroadcaster

            self._tf = StaticTransformBroadcaster(self.domain)
        self._tf.publish(transforms)

    def _why_not_sendable(self, latest: TimedSample | None) -> str | None:
        if self._writer is None:
            return "the connector is not started"
        if self._state is not LinkState.UP or latest is None:
            return f"the link is {self._state.value} (no fresh joint states on {self.joint_states_topic[2:]})"
        if self.interface == "action":
            if not self._goals.client.server_ready():
                return (
                    f"no FollowJointTrajectory action server at {self.action_name} (is '{self.controller}' loaded "
                    "and active?)"
                )
        elif self._writer.get_publication_matched_status().current_count == 0 and not (
            self._goals and self._goals.client.server_ready()
        ):
            where = f"/{self.trajectory_topic[3:]}" + (
                f" and no action server at {self.action_name}" if self._goals else ""
            )
            return f"no trajectory controller subscribes to {where} (is '{self.controller}' loaded and active?)"
        return None

    def _renew(self, now: float) -> None:
        """Give the controller the next ``horizon_s`` of the move (under ``_path_lock``): a point that far along the
        line beyond the arm's measured place on it, never behind the last one given."""
        start, target, duration_s = self._path
        latest = self._latest
        line = target - start
        length2 = float(line @ line)
        s_measured = (
            0.0
            if length2 == 0.0 or latest is None
            else float(np.clip((np.asarray(latest.joints_deg) - start) @ line / length2, 0.0, 1.0))
        )
        s_next = min(1.0, max(self._s_commanded, s_measured + self.horizon_now_s / duration_s))
        self._publish(start + s_next * line, max((s_next - s_measured) * duration_s, 0.05))
        self._s_commanded, self._renewed_s = s_next, now

    def _keep_moving(self, now: float) -> None:
        """Renew the streamed move every third of the horizon while the link is up and the move runs; the target
        once given, nothing more is needed."""
        with self._path_lock:
            move = self._moves.current
            if self._path is None:
                return
            if move is None or move.finished:
                self._path = None
                return
            if (
                self._s_commanded >= 1.0
                or self._state is not LinkState.UP
                or now - self._renewed_s < self.horizon_s / 3.0
            ):
                return
            self._renew(now)

    def _publish(self, q_user: np.ndarray, duration_s: float) -> None:
        from calib_core.ros2 import messages as msg

        point = msg.JointTrajectoryPoint(
            positions=[float(v) for v in q_user / self._per_si], time_from_start=msg.Duration.of_s(duration_s)
        )
        # An empty stamp: the controller starts the trajectory on receipt (its own clock, not ours).
        trajectory = msg.JointTrajectory(msg.Header(), list(self.joint_names), [point])
        if self._through_action:
            self._goals.send(trajectory)
        else:
            self._writer.write(trajectory)

    # --- the reader thread ---------------------------------------------------------------------
    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                for message in self._taker.take(100, 0.02):
                    self._on_joint_state(message)
            except Exception as exc:  # a DDS hiccup must not end the thread: reported, retried
                self.stats.errors += 1
                self.last_error = f"reading {self.joint_states_topic[2:]}: {exc!r}"
                time.sleep(0.05)
            now = time.monotonic()
            self._watch(now)
            self._keep_moving(now)
            self._hear_the_controller()

    def _hear_the_controller(self) -> None:
        """The action's answers: a refused or aborted goal of the move under way ends it with the controller's
        reason."""
        if self._goals is None or not self._through_action:
            return
        try:
            reason = self._goals.poll()
        except Exception as exc:  # a DDS hiccup must not end the thread
            self.stats.errors += 1
            self.last_error = f"reading {self.action_name}: {exc!r}"
            return
        if reason is not None:
            with self._path_lock:
                self._path = None
            self._moves.finish(MoveError(reason))

    def _watch(self, now: float) -> None:
        if self._state is LinkState.CONNECTING and now - self._types_checked_s >= TYPE_CHECK_S:
            self._say_foreign_types(now)
        last = self._last_sample_s
        if (
            self._state is LinkState.UP
            and last is not None
            and now - last > self.stale_after_s + self._arrival.spread_s
        ):
            self._set_state(LinkState.STALE, f"no joint states for {now - last:.1f} s")
            # A move under way cannot be followed any more: it ends now, not at its deadline (it is not renewed either).
            self._moves.finish(MoveError(f"the joint states stopped ({now - last:.1f} s): the robot's pose is unknown"))
        move = self._moves.current
        if move is not None and now > move.deadline_s:
            from calib_core.connectors.link_types import MoveTimeout

            self._moves.finish(MoveTimeout("the joints did not reach the target in time"))

    def _say_foreign_types(self, now: float) -> None:
        """Nothing has come yet: a publisher of another message type on the topic is said, not waited for."""
        self._types_checked_s = now
        from calib_core.ros2 import messages as msg

        foreign = self._types.foreign(self.joint_states_topic, msg.JointState.__idl_typename__)
        if foreign:
            self.last_error = (
                f"{self.joint_states_topic[2:]} on ROS domain {self.domain} carries {', '.join(foreign)}, not "
                "sensor_msgs/msg/JointState: "
                "name the topic of the arm's joint states (ros2:///TOPIC)"
            )
            self._restate(self.last_error)

    def _on_joint_state(self, message) -> None:
        names = list(message.name)
        if len(message.position) != len(names):
            self.stats.malformed += 1
            return
        index = {name: i for i, name in enumerate(names)}
        if any(name not in index for name in self.joint_names):
            self.stats.wrong_joint_count += 1  # another group's states (a gripper): not this arm's
            if self._state is not LinkState.UP and self.stats.wrong_joint_count % 50 == 1:
                # said while nothing usable has come: "waiting" while 477 messages arrived helped nobody
                self.last_error = foreign_joints_text(self.joint_states_topic[2:], names, self.joint_names)
                self._restate(self.last_error)
            return
        q_si = np.array([message.position[index[name]] for name in self.joint_names], dtype=float)
        if not np.all(np.isfinite(q_si)):
            self.stats.non_finite += 1
            return
        q = q_si * self._per_si
        t_ns = message.header.stamp.ns()
        sample = TimedSample(
            JointSample(next(self._seq), t_ns // 1_000_000, tuple(float(v) for v in q)), time.monotonic()
        )
        self._arrival.add(t_ns / 1e9, time.time())
        with self._lock:
            if not self._order.admit(sample.sample):
                return
            self.stats.sentences += 1
            self.stats.samples += 1
            self._latest = sample
        self._last_sample_s = sample.t_host_s
        if self._state is not LinkState.UP:
            self._set_state(LinkState.UP, "joint states arriving")
        self._emit(self.sample_received, sample)
        move = self._moves.current
        if move is not None and float(np.max(np.abs(q - np.asarray(move.joints_deg)))) <= self.done_tolerance_deg:
            self._moves.finish(None)


def open_ros2(url: str, context: ControllerContext) -> Ros2TrajectoryController:
    """Entry point of ``videocal.controllers`` for ``ros2://``."""
    return Ros2TrajectoryController(url, context)
