"""A link only the operator commands: STP stops a move, the dead-man stops one whose workstation went
silent (the link closed mid-move), ERR replies go to the move they name, a DON without its ACK is not
believed, move ids differ between sessions, and samples going backwards are not the robot now."""

import time
from pathlib import Path

import numpy as np
import pytest

from calib_core.connectors.link_types import LinkState, MoveError
from calib_core.link.driver import ControllerLink
from calib_core.link.protocol import Ack, Done, ErrorReply, JointSample, encode
from videocal_sim.controller_sim import ControllerLogic


class _Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_the_controller_stops_on_stp_and_on_a_silent_workstation():
    clock = _Clock()
    c = ControllerLogic(clock=clock)
    assert c.handle("HBT,500") == []  # the dead-man armed: 0.5 s
    assert c.handle("MVJ,a.1,90,0,0,0,0,0") == [Ack("MVJ", "a.1")]
    clock.t += 0.3
    c.handle("HBT,500")
    clock.t += 0.4  # 0.4 s since the last heartbeat: still moving
    assert not any(isinstance(m, ErrorReply) for m in c.tick()) and c.move is not None
    clock.t += 0.2  # 0.6 s: the dead-man stops the move where the robot is
    out = c.tick()
    assert out[0].code == "DEADMAN" and out[0].text.startswith("move a.1:") and c.move is None
    stopped = c.joints_deg.copy()
    assert 0.0 < stopped[0] < 90.0
    clock.t += 1.0
    c.tick()
    assert np.array_equal(c.joints_deg, stopped)  # at rest
    assert c.handle("MVJ,a.2,0,0,0,0,0,0")[0].code == "DEADMAN"  # no heartbeat: no new move either
    c.handle("HBT,500")
    assert c.handle("MVJ,a.3,0,0,0,0,0,0") == [Ack("MVJ", "a.3")]
    clock.t += 0.01
    out = c.handle("STP")
    assert (
        out[0].code == "STOPPED"
        and out[0].text.startswith("move a.3:")
        and out[-1] == Ack("STP", "-")
        and c.move is None
    )
    c.handle("HBT,0")  # disarmed
    clock.t += 10.0
    assert c.handle("MVJ,a.4,1,0,0,0,0,0") == [Ack("MVJ", "a.4")]


def test_a_link_closed_mid_move_leaves_the_robot_stopped(sim):  # noqa: F811
    s = sim("--pty", "--joints", "0,0,0,0,0,0")
    with ControllerLink(s.url, rate_hz=50, deadman_ms=300) as link:
        assert link.wait_for_samples(3, 5.0)
        link.move_joints((150.0, 0, 0, 0, 0, 0), timeout_s=20)
        deadline = time.monotonic() + 5
        while link.latest.joints_deg[0] < 5.0 and time.monotonic() < deadline:
            time.sleep(0.01)
    # The workstation is gone (closed without STP would do the same: the heartbeat stops).
    with ControllerLink(s.url, rate_hz=50) as again:
        assert again.wait_for_samples(3, 5.0)
        first = np.array(again.latest.joints_deg)
        time.sleep(0.5)
        assert again.wait_for_samples(again.stats.samples + 3, 2.0)
        assert np.allclose(again.latest.joints_deg, first, atol=1e-6) and first[0] < 150.0  # stopped, not at its goal


def test_stop_ends_the_running_move_with_the_controllers_reason(sim):  # noqa: F811
    s = sim("--pty", "--joints", "0,0,0,0,0,0")
    with ControllerLink(s.url, rate_hz=50) as link:
        assert link.wait_for_samples(3, 5.0)
        handle = link.move_joints((150.0, 0, 0, 0, 0, 0), timeout_s=20)
        while not handle.acked:
            time.sleep(0.005)
        assert link.stop()
        with pytest.raises(MoveError, match=rf"STOPPED: move {handle.id}: stopped by the workstation"):
            handle.wait(5)


def test_replies_are_matched_by_id_and_samples_going_back_are_not_fresh():
    link = ControllerLink(
        "loop://", rate_hz=10, deadman_ms=0, n_joints=1, key=None
    )  # no controller: nothing to authenticate with
    delivered = []
    link.sample_received.connect(delivered.append)
    link.start(wait_open=True)
    try:
        first, second = link.move_joints((1.0,)), link.move_joints((2.0,))
        assert first.id != second.id and first.id.startswith(f"m{link._session}.")
        now = time.monotonic()
        link._dispatch(ErrorReply("LIMIT", f"move {second.id}: outside").body(), now)  # names the second
        assert second.finished and "outside" in str(second.error) and not first.finished
        link._dispatch(Done(first.id).body(), now)  # no ACK yet: not believed
        assert not first.finished and link.stats.errors == 2
        link._dispatch(Ack("MVJ", first.id).body(), now)
        link._dispatch(Done(first.id).body(), now)
        assert first.finished and first.error is None
        for seq, t_ms in ((10, 5000), (11, 5020), (11, 5020), (9, 4980), (12, 5010), (0, 20)):
            link._dispatch(JointSample(seq, t_ms, (0.0,)).body(), now)
        assert [d.sample.seq for d in delivered] == [
            10,
            11,
            0,
        ]  # a repeat, an older one, a time going back: dropped; a restart: fresh
        assert link.stats.backwards_samples == 3 and link.stats.controller_restarts == 1
    finally:
        link.close()
    assert link.state is LinkState.CLOSED
    assert encode("STP").startswith(b"$STP*")


def test_a_second_workstation_cannot_take_the_robot_over(sim):  # noqa: F811
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    sim("--tcp", str(port), link=False)
    url = f"socket://127.0.0.1:{port}"
    with ControllerLink(url, rate_hz=50) as first:
        assert first.wait_for_samples(3, 5.0)
        with socket.create_connection(("127.0.0.1", port), timeout=5) as intruder:
            intruder.sendall(encode("MVJ,x.1,90,0,0,0,0,0"))
            answer = intruder.recv(4096)
            assert b"ERR,BUSY,another workstation is connected" in answer
        time.sleep(0.3)
        assert np.allclose(first.latest.joints_deg, 0.0)  # the intruder's move did not run
        assert first.state is LinkState.UP
    with ControllerLink(url, rate_hz=50) as second:  # once the first is gone, the next one gets in
        assert second.wait_for_samples(3, 5.0)


def test_a_pending_move_times_out_while_the_link_is_down(sim):  # noqa: F811
    from calib_core.connectors.link_types import MoveTimeout

    s = sim("--pty", "--joints", "0,0,0,0,0,0")
    with ControllerLink(s.url, rate_hz=50, deadman_ms=300) as link:
        assert link.wait_for_samples(3, 5.0)
        handle = link.move_joints((150.0, 0, 0, 0, 0, 0), timeout_s=1.5)
        s.proc.kill()  # the controller is gone for good: the link stays down, reconnecting
        s.proc.wait(5)
        # ... and its device with it: a killed pty's number is soon another program's pty on a busy machine (another
        # suite's simulator), which the link would open again through the path left behind and find samples on
        Path(s.url).unlink(missing_ok=True)
        deadline = time.monotonic() + 15
        while not handle.finished and time.monotonic() < deadline:
            time.sleep(0.02)
        # (reconnecting: down between its attempts, connecting during one; never up)
        assert link.state in (LinkState.DOWN, LinkState.CONNECTING)
        assert handle.finished and isinstance(handle.error, MoveTimeout) and handle.id in str(handle.error)
