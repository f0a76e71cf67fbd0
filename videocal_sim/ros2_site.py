"""The simulated cell over ROS 2: the robot is a simulated ros2_control arm in a child process
(``videocal sim-ros2``) and the gripper camera is published as ``sensor_msgs/Image`` with its CameraInfo, so
the operator core reaches both only through its ROS 2 connectors (``ros2:///joint_states``,
``ros2:///camera/image_raw``), on Cyclone DDS, as it would a real cell's.

The camera publisher runs here (it renders the test bed's true view, which is the truth and stays in
``videocal_sim``); it poses the camera from the joint states the core receives, as the simulated site does.

Far away (``weather``): the arm runs in a network namespace of its own behind
:class:`~videocal_sim.far_network.FarNetwork`,
every DDS packet between it and the workstation delayed, jittered and some dropped; the camera publisher stays on the
workstation's side and renders where the joint states put the robot as they arrive, each frame stamped with the
stamp of the joint state it shows (so the picture and its stamp agree however late the states came).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

import numpy as np

from videocal_sim.sim_process import _PROJECT, SiteError, _die_with_parent, stop_child
from videocal_sim.sim_site import SimulatedSite


class Ros2ArmProcess:
    """``videocal sim-ros2`` for a cell, a child that dies with us; :meth:`wait_ready` waits for its ``ready``."""

    def __init__(self, workcell_path: Path, joints_deg, domain: int, rate_hz: float = 100.0, *, network=None):
        self._folder = tempfile.TemporaryDirectory(prefix="videocal-sim-ros2-")
        self._stderr_path = Path(self._folder.name) / "stderr.txt"
        cmd = [
            sys.executable,
            "-m",
            "app.cli.main",
            "sim-ros2",
            "--workcell",
            str(Path(workcell_path).resolve()),
            "--domain",
            str(domain),
            "--rate",
            f"{rate_hz:g}",
            # one token: a first joint below zero would otherwise read as an option ("expected one argument")
            "--joints=" + ",".join(f"{v:.6f}" for v in joints_deg),
        ]
        env = None
        if network is not None:  # on the far side of the link, with its own address and the workstation as its peer
            cmd = network.far_command(cmd)
            env = dict(os.environ, CYCLONEDDS_URI=network.cyclone_config("far"))
        with open(self._stderr_path, "w") as err:
            self.process = subprocess.Popen(
                cmd,
                stdout=subprocess.PIPE,
                stderr=err,
                stdin=subprocess.DEVNULL,
                text=True,
                cwd=str(_PROJECT),
                env=env,
                preexec_fn=_die_with_parent,
            )
        self._ready = False

    def wait_ready(self) -> None:
        if not self._ready:
            if self.process.stdout.readline().strip() != "ready":
                self.process.wait(timeout=5)
                why = self._stderr_path.read_text().strip().splitlines()
                raise SiteError(
                    "the simulated ROS 2 arm did not start: "
                    f"{why[-1] if why else f'exit code {self.process.returncode}'}"
                )
            self._ready = True

    def stop(self) -> None:
        stop_child(self.process)
        self._folder.cleanup()


class CameraPublisher:
    """Publishes ``source``'s frames on ``/camera/image_raw`` (rgb8) and ``intrinsics`` (the cell's camera file, as
    a driver publishes its calibration file) on ``/camera/camera_info``, until :meth:`stop`. Each frame is stamped
    ``stamp_ns(q)`` (epoch ns) of the joints ``q`` it was rendered at (``source.last_truth``): the stamp of that joint
    state, so the picture and its stamp agree however late the joint states came (a far link's)."""

    def __init__(self, source, intrinsics, domain: int, stamp_ns):
        self.source, self.intrinsics, self.domain, self.stamp_ns = source, intrinsics, domain, stamp_ns
        self.published = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sim ros2 camera", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        from cyclonedds.pub import DataWriter
        from cyclonedds.topic import Topic

        from calib_core.ros2 import messages as msg
        from calib_core.ros2.participant import participant
        from calib_core.ros2.wire import default_qos, sensor_qos

        dp = participant(self.domain)
        images = DataWriter(dp, Topic(dp, "rt/camera/image_raw", msg.Image), qos=sensor_qos(1))
        infos = DataWriter(dp, Topic(dp, "rt/camera/camera_info", msg.CameraInfo), qos=default_qos(1))
        i = self.intrinsics
        k = [i.fu, 0.0, i.cx, 0.0, i.fv, i.cy, 0.0, 0.0, 1.0]
        period = 1.0 / self.source.fps if self.source.fps else 0.0
        next_s = time.monotonic()
        while not self._stop.is_set():
            next_s = max(
                next_s + period, time.monotonic() - period
            )  # at the camera's rate (behind: no burst to catch up)
            self._stop.wait(max(0.0, next_s - time.monotonic()))
            frame = self.source.read()
            if frame is None:
                break
            h, w = frame.image.shape[:2]
            stamp = msg.Time.of_ns(self.stamp_ns(self.source.last_truth.q_commanded_deg))
            header = msg.Header(stamp, "camera")
            images.write(msg.Image(header, h, w, "rgb8", 0, w * 3, frame.image.tobytes()))
            infos.write(
                msg.CameraInfo(
                    header,
                    h,
                    w,
                    i.model,
                    [float(v) for v in i.distortion],
                    k,
                    [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0],
                    [i.fu, 0.0, i.cx, 0.0, 0.0, i.fv, i.cy, 0.0, 0.0, 0.0, 1.0, 0.0],
                )
            )
            self.published += 1
        self.source.close()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=3.0)


PRIVATE_DOMAINS = (71, 100)
"""The DDS domains a simulated arm takes when none is named: away from ROS 2's default (0) and the small ones people
pick, so a demo never commands, or is commanded by, a real robot on the workstation's own domain; and within ROS 2's
safe range (0-101 on Linux: a higher domain's ports fall in the ephemeral range, where another socket may hold one)."""


def private_domain() -> int:
    """A domain for this process's simulated cell: within :data:`PRIVATE_DOMAINS`, by the process id (two demos at
    once take two domains)."""
    low, high = PRIVATE_DOMAINS
    return low + os.getpid() % (high - low + 1)


class Ros2SimulatedSite(SimulatedSite):
    """A :class:`SimulatedSite` whose robot and camera are reached through ROS 2: on ``domain``, else on
    ``ROS_DOMAIN_ID`` when the user set it, else on a private domain (:func:`private_domain`)."""

    def __init__(self, site: SimulatedSite, domain: int | None = None, weather=None, seed: int = 0):
        super().__init__(site.bed, camera_fps=site.camera_fps, camera_seed=site.camera_seed)
        from calib_core.ros2.wire import domain_id

        private = domain is None and "ROS_DOMAIN_ID" not in os.environ
        self.domain = private_domain() if private else domain_id(domain)
        self.description = (
            f"simulated cell {self.bed.workcell.name} over ROS 2 (domain {self.domain}"
            + (", a private one: set ROS_DOMAIN_ID to choose" if private else "")
            + ")"
        )
        self.arm: Ros2ArmProcess | None = None
        self.publisher: CameraPublisher | None = None
        self.network = None
        self._poses: deque[tuple[np.ndarray, int]] = deque(
            [(self.bed.joints_deg.copy(), time.time_ns())], maxlen=256
        )  # (joints, stamp ns)
        if weather is not None:
            from calib_core.ros2.participant import configure
            from videocal_sim.far_network import FarNetwork

            self.network = FarNetwork(weather, seed=seed)
            configure(self.domain, self.network.cyclone_config("near"))
            self.description += (
                f", {1000 * weather.one_way_s:.0f} ms away (+-{100 * weather.jitter:.0f} %, "
                f"{100 * weather.loss:g} % of the packets lost)"
            )

    def _follow(self, sample) -> None:
        # The robot is where its joint states say, at their stamp (the controller's epoch clock), kept as a pair so
        # that a frame rendered from those joints is stamped with their time.
        joints = self._link_joint_map.to_model(sample.joints_deg)
        self._poses.append((joints, int(sample.sample.t_ms) * 1_000_000))
        self.bed.joints_deg = joints

    def _stamp_of(self, q_deg) -> int:
        """The stamp (epoch ns) of the newest joint state at exactly ``q_deg``: the one the frame was rendered from."""
        for joints, stamp_ns in reversed(list(self._poses)):
            if np.array_equal(joints, q_deg):
                return stamp_ns
        return self._poses[-1][1]

    def start_controller(self) -> str:
        if self.arm is None:
            self.arm = Ros2ArmProcess(self.bed.workcell.path, self.bed.joints_deg, self.domain, network=self.network)
        self.arm.wait_ready()
        return f"ros2:///joint_states?domain={self.domain}"

    def camera_factory(self, fps: float | None = None) -> Callable:
        if self.publisher is None:
            camera = self.bed.camera(fps=fps or self.camera_fps, seed=self.camera_seed, live=True)
            self.publisher = CameraPublisher(camera, self.bed.intrinsics, self.domain, self._stamp_of)
        from calib_core.connectors.registry import open_camera

        spec = f"ros2:///camera/image_raw?domain={self.domain}"
        return lambda: open_camera(spec)

    def close(self) -> None:
        if self.publisher is not None:
            self.publisher.stop()
        if self.arm is not None:
            self.arm.stop()
        if self.network is not None:
            from calib_core.ros2.participant import release

            release(self.domain)
            self.network.close()
