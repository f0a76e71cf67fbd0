"""ROS 2 seconds away: the simulated ros2_control arm in a network namespace of its own,
every DDS packet between it and this process delayed 1.5 s one way (+-30 %), 1 % of them dropped, by
:class:`videocal_sim.far_network.FarNetwork`. The connector must come up, measure the delay from the stamps,
take no burst of late samples for a lost robot, and move the arm once along its line to the target."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np
import pytest

from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState
from calib_core.operator.cell import Cell
from calib_core.ros2.participant import configure, release
from calib_core.workcell import DEFAULT_WORKCELL
from videocal_sim.delay_line import LinkWeather
from videocal_sim.far_network import FarNetwork, why_not_available
from tests.waiting import wait_until

pytestmark = pytest.mark.skipif(why_not_available() is not None, reason=f"no far network here: {why_not_available()}")

_PROJECT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def test_a_far_network_delays_and_drops_udp_between_its_two_sides():
    """The link's own check: datagrams from the far side arrive no earlier than the delay's lower bound, in order,
    and about the weather's share of them is lost."""
    import socket

    with FarNetwork(LinkWeather(0.2, 0.3, 0.1), seed=3) as net:
        receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        receiver.bind((net.near_ip, 0))
        receiver.settimeout(3.0)
        port = receiver.getsockname()[1]
        sender = (
            f"import socket, time\ns = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n"
            f"for i in range(200):\n    s.sendto(f'{{i}} {{time.monotonic()}}'.encode(), ('{net.near_ip}', {port}))\n  "
            "  time.sleep(0.002)\n"
        )
        subprocess.run(net.far_command([sys.executable, "-c", sender]), check=True, timeout=30)
        got = []
        try:
            while True:
                data = receiver.recv(100).decode().split()
                got.append((int(data[0]), time.monotonic() - float(data[1])))
        except TimeoutError:
            pass
    numbers = [i for i, _ in got]
    assert numbers == sorted(numbers)
    assert 200 * 0.8 <= len(got) < 200  # 10 % dropped: 20 expected
    assert min(delay for _, delay in got) >= 0.2 * 0.7 - 0.01


def test_the_ros2_connector_moves_an_arm_seconds_away_once_along_its_line(domain):
    weather = LinkWeather(1.5, 0.3, 0.01)
    cell = Cell.open(DEFAULT_WORKCELL)
    robot = cell.robot
    with FarNetwork(weather, seed=5) as net:
        configure(domain, net.cyclone_config("near"))
        cmd = [
            sys.executable,
            "-m",
            "app.cli.main",
            "sim-ros2",
            "--domain",
            str(domain),
            "--joints",
            ",".join("0" for _ in range(robot.n_joints)),
        ]
        arm = subprocess.Popen(
            net.far_command(cmd),
            cwd=_PROJECT,
            env=dict(os.environ, CYCLONEDDS_URI=net.cyclone_config("far")),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        link = None
        try:
            assert arm.stdout.readline().strip() == "ready", arm.stderr.read()
            context = ControllerContext(
                robot.joint_names, robot.joint_units, JointMap.identity(robot.n_joints), 100.0, {}
            )
            link = open_controller(f"ros2:///joint_states?domain={domain}", context)
            states, samples = [], []
            link.state_changed.connect(lambda state, why: states.append(state))
            link.sample_received.connect(lambda s: samples.append(np.asarray(s.joints_deg)))
            link.start()
            assert wait_until(lambda: link.state is LinkState.UP, timeout_s=40.0)  # discovery crosses the link too
            assert wait_until(lambda: len(samples) > 300, timeout_s=20.0)
            # The delay from the stamps: the weather's, within its jitter (in order, so nearer its upper end).
            assert 1.5 * 0.7 <= link.delay_s <= 1.5 * 1.3 + 0.1
            assert link.horizon_now_s > 2.0 * link.delay_s  # the move is given more than the round trip
            target = np.zeros(robot.n_joints)
            target[0], target[2] = 25.0, -15.0
            start = len(samples)
            handle = link.move_joints(target, timeout_s=60.0)
            assert handle.sent
            handle.wait(60.0)
            # Along its line, never back, never past the target: each message replaced the last, none ran twice.
            along = np.array([q @ target / (target @ target) for q in samples[start:]])
            # Done as the connector calls it done: every joint within its done tolerance of the target.
            assert np.max(np.abs(samples[-1] - target)) <= link.done_tolerance_deg
            assert np.all(np.diff(along) >= -1e-6) and np.all(along <= 1.0 + 1e-6)
            assert LinkState.STALE not in states  # no late burst taken for a lost robot
        finally:
            if link is not None:
                link.close()
            release(domain)
            arm.terminate()
            arm.wait(timeout=5)
