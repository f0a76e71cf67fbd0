"""The link attacks tried again through a far link: the workstation 1 s away (+-30 %, 1 % lost) through a delay
line, the simulated controller on its TCP port, and a keyless host next to the controller flooding it with
connections, old-style hellos and wrong proofs; then the controller pulled off the network and back."""

from __future__ import annotations

import re
import socket
import threading

import numpy as np
import pytest

from calib_core.connectors.link_types import LinkState, MoveError
from calib_core.link.driver import ControllerLink
from calib_core.link.protocol import encode
from calib_core.link.workstation_auth import AuthState
from tests.core.link.sim_process import SimProcess
from tests.waiting import wait_until
from videocal_sim.delay_line import DelayLine, LinkWeather

WEATHER = LinkWeather(1.0, 0.3, 0.01)
FLOOD_HOST = "127.0.0.2"  # another host than the workstation's relay (loopback answers all of 127/8)


class _Flood:
    """A keyless host opening a connection every 20 ms and keeping it, each sending an old-style hello and a wrong
    proof, until stopped; ``connects`` counts them."""

    def __init__(self, port: int):
        self.port, self.connects = port, 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        held = []
        while not self.stop.is_set():
            try:
                sock = socket.create_connection(("127.0.0.1", self.port), timeout=1.0, source_address=(FLOOD_HOST, 0))
                sock.sendall(encode("HEL,0123456789abcdef") + encode("AUT," + "0" * 64))
                held.append(sock)
                self.connects += 1
            except OSError:
                pass  # refused, or the controller is away: try again
            held = held[-40:]
            self.stop.wait(0.02)
        for sock in held:
            sock.close()

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join(5.0)


@pytest.fixture
def far_port():
    """A free TCP port for the controller, and a delay line to it: (port, the workstation's URL, start the
    controller, the line)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    started: list[SimProcess] = []

    def start() -> SimProcess:
        sim = SimProcess("--tcp", str(port), "--joints", "0,0,0,0,0,0")
        assert re.search(rf":{port}\b", sim.device)
        started.append(sim)
        return sim

    line = DelayLine(("127.0.0.1", 0), ("127.0.0.1", port), WEATHER, seed=11).start()
    try:
        yield port, f"socket://{line.address[0]}:{line.address[1]}", start
    finally:
        line.close()
        for sim in started:
            sim.stop()


def test_a_flood_of_keyless_connections_does_not_keep_a_far_workstation_from_its_session(far_port):
    """Each keyless connection once displaced the workstation's before its hello had crossed the link: 1 s away, a
    connection every 0.3 s kept it out for 40 s. Under a flood every 20 ms the session opens and moves are made and
    confirmed, none refused."""
    port, url, start = far_port
    start()
    with _Flood(port) as flood, ControllerLink(url, rate_hz=50) as workstation:
        assert workstation._auth.wait_settled(40.0) is AuthState.READY, workstation.auth_failure
        for goal in (12.0, -9.0):
            workstation.move_joints((goal, 0, 0, 0, 0, 0), timeout_s=40.0).wait(40.0)  # raises if refused
            assert wait_until(lambda: abs(workstation.latest.joints_deg[0] - goal) < 1e-3, 10.0)
        assert flood.connects > 100  # the flood ran all along


def test_a_controller_pulled_off_the_network_mid_move_and_back_moves_nothing_by_itself(far_port):
    """The controller goes away mid-move (its process and port gone) while the flood goes on, and comes back: the move
    in flight is not reported done, the workstation opens a new session through the flood, the robot stands where the
    controller came back and moves again only when told."""
    port, url, start = far_port
    sim = start()
    with _Flood(port), ControllerLink(url, rate_hz=50) as workstation:
        assert workstation._auth.wait_settled(40.0) is AuthState.READY, workstation.auth_failure
        in_flight = workstation.move_joints((150.0, 0, 0, 0, 0, 0), timeout_s=20.0)
        assert wait_until(lambda: workstation.latest.joints_deg[0] > 1.0, 20.0)  # under way
        sim.stop()  # pulled
        with pytest.raises(MoveError):
            in_flight.wait(25.0)  # never confirmed done: it did not finish
        assert wait_until(lambda: workstation.state is not LinkState.UP, 20.0)
        start()  # back: a controller that forgot its move and its session
        assert wait_until(lambda: workstation.state is LinkState.UP, 40.0)
        assert wait_until(lambda: workstation.auth_state is AuthState.READY, 40.0), workstation.auth_failure
        standing = np.asarray(workstation.latest.joints_deg, dtype=float)
        assert wait_until(lambda: workstation.stats.samples > 0, 5.0)
        before = workstation.stats.samples
        assert wait_until(lambda: workstation.stats.samples > before + 50, 20.0)  # a second of samples
        assert np.allclose(workstation.latest.joints_deg, standing, atol=1e-6)  # nothing moved by itself
        workstation.move_joints((5.0, 0, 0, 0, 0, 0), timeout_s=40.0).wait(40.0)
        assert wait_until(lambda: abs(workstation.latest.joints_deg[0] - 5.0) < 1e-3, 10.0)
