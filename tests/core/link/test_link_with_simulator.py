"""The driver against the simulator as a real subprocess on a pty and on TCP: polling and
streaming, moves (ACK/DON, ERR, timeout), fault injection, disconnect and reconnect, shutdown."""

import socket
import threading
import time

import numpy as np
import pytest

from calib_core.connectors.link_types import LinkError, LinkState, MoveError, MoveTimeout
from calib_core.link.driver import ControllerLink


def _link_threads():
    return [t for t in threading.enumerate() if t.name.startswith("controller-link")]


def test_streaming_delivers_ordered_samples_and_closes_quickly(sim):
    s = sim("--pty")
    link = ControllerLink(s.url, mode="stream", rate_hz=100).start(wait_open=True)
    assert link.wait_for_samples(50, 5.0)
    samples = link.drain()
    seqs = [x.sample.seq for x in samples]
    assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))
    assert link.state is LinkState.UP
    stats = link.stats_snapshot()
    assert stats["bad_checksum"] == 0 and stats["seq_gaps"] == 0
    t0 = time.monotonic()
    link.close()
    assert time.monotonic() - t0 < 1.0
    assert not _link_threads() and link.state is LinkState.CLOSED


def test_polling_gets_one_sample_per_request(sim):
    s = sim("--pty")
    with ControllerLink(s.url, mode="poll", rate_hz=40) as link:
        assert link.wait_for_samples(20, 5.0)
        t = [x.t_host_s for x in link.drain()]
        # About 40 Hz: the samples are spaced by the polling period, not streamed in bursts.
        assert 0.015 < np.median(np.diff(t)) < 0.04


def test_move_is_acked_runs_and_finishes(sim):
    s = sim("--pty", "--joints", "0,0,0,0,0,0")
    with ControllerLink(s.url, rate_hz=100) as link:
        assert link.wait_for_samples(3, 5.0)
        target = (10.0, -5.0, 3.0, 0.0, 20.0, -15.0)
        handle = link.move_joints(target, timeout_s=10)
        handle.wait(10)
        assert handle.acked
        time.sleep(0.05)
        assert np.allclose(link.latest.joints_deg, target, atol=1e-4)
        seen = np.array([x.joints_deg for x in link.drain()])
        # The joints passed through intermediate positions (a trapezoid, not a jump).
        assert np.any((np.abs(seen[:, 4]) > 1.0) & (np.abs(seen[:, 4]) < 19.0))


def test_refused_move_raises_with_the_controllers_text(sim):
    s = sim("--pty")
    with ControllerLink(s.url) as link:
        assert link.wait_for_samples(1, 5.0)
        handle = link.move_joints((0, 0, 500.0, 0, 0, 0), timeout_s=5)
        with pytest.raises(MoveError, match=r"LIMIT: move m[0-9a-f]{4}\.1: joint 3 target 500.00 outside"):
            handle.wait(5)


def test_move_without_done_times_out(sim):
    s = sim("--pty")
    with ControllerLink(s.url) as link:
        assert link.wait_for_samples(1, 5.0)
        handle = link.move_joints((160, 160, 160, 160, 160, 160), timeout_s=0.3)
        with pytest.raises(MoveTimeout, match="no DON before its timeout"):
            handle.wait(5)


@pytest.mark.parametrize(
    "fault, counter",
    [("--corrupt-rate", "bad_checksum"), ("--noise-rate", "garbage_bytes"), ("--drop-rate", "missing_samples")],
)
def test_fault_injection_is_survived_and_counted(sim, fault, counter):
    s = sim("--pty", fault, "0.2", "--seed", "3")
    with ControllerLink(s.url, rate_hz=200) as link:
        assert link.wait_for_samples(200, 10.0)
        seqs = [x.sample.seq for x in link.drain()]
        stats = link.stats_snapshot()
    assert stats[counter] > 0
    assert all(b > a for a, b in zip(seqs, seqs[1:]))  # in order, never twice
    if fault == "--corrupt-rate":
        # A flipped byte never passes as a sample: every delivered sample is one the controller sent.
        assert stats["samples"] == len(seqs)


def test_non_finite_and_unknown_sentences_are_counted(sim):
    from calib_core.link.protocol import encode

    link = ControllerLink("loop://", rate_hz=50, reconnect=False).start(wait_open=True)
    try:
        for body in ("JNT,1,5,0,0,nan,0,0,0", "XYZ,1,2", "JNT,2,6,1,2,3,4,5,6"):
            link._port.write(encode(body))
        assert link.wait_for_samples(1, 2.0)
        time.sleep(0.1)
        stats = link.stats_snapshot()
        assert stats["non_finite"] == 1 and stats["unknown"] == 1 and stats["samples"] == 1
        assert link.latest.joints_deg == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
    finally:
        link.close()


def test_pty_reboot_reconnects_and_samples_resume(sim):
    s = sim("--pty", "--reboot-after", "1.0", "--reboot-downtime", "0.5")
    states = []
    with ControllerLink(s.url, rate_hz=100) as link:
        link.state_changed.connect(lambda state, why: states.append(state))
        assert link.wait_for_samples(20, 5.0)
        s.next_announcement()
        gone = time.monotonic()
        while link.state is not LinkState.DOWN and time.monotonic() - gone < 3:
            time.sleep(0.01)
        assert link.state in (LinkState.DOWN, LinkState.CONNECTING, LinkState.UP)
        before = link.stats.samples
        deadline = time.monotonic() + 4.0
        while link.stats.samples <= before + 10 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert link.stats.samples > before + 10
        assert link.stats.reconnects >= 1
    assert LinkState.DOWN in states and states[-1] is LinkState.CLOSED


def test_tcp_server_restart(sim):
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    s = sim("--tcp", str(port), link=False)
    link = ControllerLink(f"socket://127.0.0.1:{port}", rate_hz=100).start(wait_open=True)
    try:
        assert link.wait_for_samples(10, 5.0)
        s.stop()
        deadline = time.monotonic() + 3
        while link.state is not LinkState.DOWN and time.monotonic() < deadline:
            time.sleep(0.01)
        assert link.state is LinkState.DOWN
        restarted = time.monotonic()
        sim("--tcp", str(port), link=False)
        before = link.stats.samples
        while link.stats.samples < before + 10 and time.monotonic() - restarted < 4:
            time.sleep(0.01)
        assert link.stats.samples >= before + 10
        assert time.monotonic() - restarted < 3.0
    finally:
        link.close()


def test_unusable_urls():
    with pytest.raises(LinkError, match="unusable link URL"):
        ControllerLink("bogus://nowhere")
    with pytest.raises(LinkError, match="cannot open /dev/does-not-exist"):
        ControllerLink("/dev/does-not-exist").start(wait_open=True)
