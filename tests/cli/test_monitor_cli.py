"""``videocal monitor`` and ``videocal sim-controller`` as a user runs them."""

import json
import subprocess
import sys

from tests.core.link.sim_process import SimProcess


def _videocal(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "app.cli.main", *args], capture_output=True, text=True, timeout=timeout)


def test_monitor_prints_count_samples_as_json(tmp_path):
    sim = SimProcess("--pty", "--joints", "1,2,3,4,5,6", link=tmp_path / "ctl")
    try:
        run = _videocal("monitor", sim.url, "--stream", "100", "--count", "7", "--json")
        assert run.returncode == 0, run.stderr
        lines = [json.loads(line) for line in run.stdout.splitlines()]
        assert len(lines) == 7
        assert lines[0]["joints_deg"] == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
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
