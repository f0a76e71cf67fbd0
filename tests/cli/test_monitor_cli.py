"""``videocal monitor`` and ``videocal sim-controller`` as a user runs them."""

import json
import subprocess
import sys
import time

import numpy as np

from tests.core.link.sim_process import SimProcess


def _videocal(*args, timeout=60):
    return subprocess.run(
        [sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=timeout
    )


def test_monitor_prints_count_samples_as_json(tmp_path):
    sim = SimProcess("--pty", "--joints", "1,2,3,4,5,6", link=tmp_path / "ctl")
    try:
        before_ms = time.time() * 1000
        run = _videocal("monitor", sim.url, "--stream", "100", "--count", "7", "--json")
        assert run.returncode == 0, run.stderr
        lines = [json.loads(line) for line in run.stdout.splitlines()]
        assert len(lines) == 7
        assert lines[0]["joints_deg"] == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
        # t_ms counts from the epoch (the controller's own clock, since its start, put on it by the first sample's
        # arrival), apart by the controller's own steps (10 ms at 100 Hz)
        assert all(before_ms - 1000 < x["t_ms"] < time.time() * 1000 + 1000 for x in lines)
        assert all(x["t_controller_ms"] < 1_000_000_000_000 for x in lines)
        steps = np.diff([x["t_ms"] for x in lines])
        assert np.array_equal(steps, np.diff([x["t_controller_ms"] for x in lines])) and np.all(steps > 0)
        assert [x["seq"] for x in lines] == list(range(lines[0]["seq"], lines[0]["seq"] + 7))
        assert "link statistics: sentences" in run.stderr
        poll = _videocal("monitor", sim.url, "--poll", "30", "--count", "3")
        assert poll.returncode == 0 and len(poll.stdout.splitlines()) == 3
    finally:
        sim.stop()


def test_monitor_times_out_with_exit_4(tmp_path):
    sim = SimProcess("--pty", "--drop-rate", "1.0", link=tmp_path / "ctl")
    try:
        run = _videocal("monitor", sim.url, "--count", "1", "--timeout", "0.5")
        assert run.returncode == 4
        assert "no joint sample" in run.stderr
    finally:
        sim.stop()


def test_monitor_unusable_url_exits_2():
    for url in ("bogus://x", "/dev/no-such-port"):
        run = _videocal("monitor", url, "--count", "1")
        assert run.returncode == 2
        assert run.stderr.startswith("error: ") and "Traceback" not in run.stderr


def test_sim_controller_bad_options_exit_2():
    run = _videocal("sim-controller", "--pty", "--drop-rate", "2")
    assert run.returncode == 2 and "drop-rate must lie in [0, 1]" in run.stderr
    run = _videocal("sim-controller", "--tcp", "5000", "--link", "/tmp/x")
    assert run.returncode == 2 and "--link applies to --pty" in run.stderr


def test_monitor_does_not_show_a_sample_of_another_joint_count(tmp_path):
    """A 3-joint sample in the middle of a 6-joint stream was printed as if it were valid. The
    controller here is the test itself on a pty: it answers nothing but streams samples, one of them short."""
    import os
    import threading
    import tty

    from calib_core.link.protocol import JointSample, encode

    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    stop = threading.Event()

    def stream():
        seq = 0
        while not stop.is_set():
            joints = (1.0, 2.0, 3.0) if seq % 10 == 5 else (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)  # one short in ten
            os.write(master, encode(JointSample(seq, 1000 + 20 * seq, joints).body()))
            seq += 1
            time.sleep(0.02)

    writer = threading.Thread(target=stream, daemon=True)
    writer.start()
    try:
        run = _videocal("monitor", os.ttyname(slave), "--count", "12", "--json", "--timeout", "5")
    finally:
        stop.set()
        writer.join(2)
        os.close(master)
        os.close(slave)
    assert run.returncode == 0, run.stderr
    lines = [json.loads(line) for line in run.stdout.splitlines()]
    assert len(lines) == 12 and all(len(x["joints_deg"]) == 6 for x in lines)
    shown = [x["seq"] for x in lines]
    assert not any(seq % 10 == 5 for seq in shown) and shown[-1] - shown[0] >= 10  # a short one fell inside, unshown
    assert "has 3 joint values, the robot has 6: not shown" in run.stderr


def test_monitor_reads_a_ros2_arm_in_another_process(tmp_path, monkeypatch, domain):
    """``sim-ros2`` (a ros2_control arm on Cyclone DDS) and ``monitor ros2://`` as two processes: the
    samples come in the workcell's joint order, stamped by the arm's clock (ms since the epoch)."""
    import os

    from calib_core.workcell import DEFAULT_WORKCELL

    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    arm = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", "sim-ros2", "--rate", "200", "--joints", "10,-20,30,-40,50,-60"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert arm.stdout.readline().strip() == "ready"
        before_ms = time.time() * 1000
        run = subprocess.run(
            [
                sys.executable,
                "-m",
                "app.cli.main",
                "monitor",
                "ros2:///joint_states",
                "--workcell",
                str(DEFAULT_WORKCELL),
                "--count",
                "5",
                "--json",
                "--timeout",
                "20",
            ],
            capture_output=True,
            text=True,
            timeout=60,
            env=env,
        )
        assert run.returncode == 0, run.stderr
        lines = [json.loads(line) for line in run.stdout.splitlines()]
        assert len(lines) == 5
        assert [round(v, 9) for v in lines[0]["joints_deg"]] == [10.0, -20.0, 30.0, -40.0, 50.0, -60.0]
        assert all(before_ms - 60_000 < x["t_ms"] < time.time() * 1000 + 1000 for x in lines)
        assert [x["t_ms"] for x in lines] == sorted(x["t_ms"] for x in lines)
        no_cell = subprocess.run(
            [sys.executable, "-m", "app.cli.main", "monitor", "ros2:///joint_states", "--count", "1"],
            capture_output=True,
            text=True,
            timeout=60,
            env=env,
        )
        assert (
            no_cell.returncode == 2
            and "give the cell (--workcell)" in no_cell.stderr
            and "Traceback" not in no_cell.stderr
        )
    finally:
        arm.terminate()
        arm.wait(10)
