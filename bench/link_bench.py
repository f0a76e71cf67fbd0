"""Controller-link targets. Writes docs/benchmarks/link.md.

- parse rate from a pty (sentences per second through the driver, 2 cores);
- latency from a sentence's last byte written to its sample callback (median, 99th percentile);
- fuzzed input: 100 000 random garbage chunks interleaved with valid sentences;
- unplug and replug: a pty controller rebooting and a TCP server restarting.
"""

from __future__ import annotations

import os
import platform
import socket
import subprocess
import sys
import time
import tty
from pathlib import Path

import numpy as np

from calib_core.link.assembler import SentenceAssembler
from calib_core.link.driver import ControllerLink
from calib_core.connectors.link_types import LinkState
from calib_core.link.protocol import JointSample, encode

OUT = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "link.md"


def _pty_pair():
    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    return master, os.ttyname(slave), slave


def parse_rate() -> tuple[float, int]:
    """Sentences per second the driver takes from a pty fed as fast as the pty accepts."""
    master, path, slave = _pty_pair()
    n = 20_000
    data = b"".join(encode(JointSample(i, i, (1.2345, -2.5, 33.3333, 0.0, 90.0, -179.9999)).body()) for i in range(n))
    link = ControllerLink(path, mode="stream", rate_hz=250, stale_after_s=10).start(wait_open=True)
    time.sleep(0.2)
    t0 = time.perf_counter()
    view = memoryview(data)
    sent = 0
    while sent < len(data):
        sent += os.write(master, view[sent : sent + 4096])
    link.wait_for_samples(n, 30.0)
    elapsed = time.perf_counter() - t0
    got = link.stats.samples
    link.close()
    os.close(master)
    os.close(slave)
    return got / elapsed, got


def latency() -> tuple[float, float]:
    """Last byte written to the pty -> sample callback, at 200 samples/s, ms."""
    master, path, slave = _pty_pair()
    arrivals: dict[int, float] = {}
    link = ControllerLink(path, mode="stream", rate_hz=250, stale_after_s=10)
    link.sample_received.connect(lambda s: arrivals.__setitem__(s.sample.seq, time.perf_counter()))
    link.start(wait_open=True)
    time.sleep(0.2)
    sent_at = {}
    for i in range(1000):
        sentence = encode(JointSample(i, i, (0.0,) * 6).body())
        os.write(master, sentence)
        sent_at[i] = time.perf_counter()
        time.sleep(0.005)
    time.sleep(0.2)
    link.close()
    os.close(master)
    os.close(slave)
    lat = np.array([arrivals[i] - sent_at[i] for i in sent_at if i in arrivals]) * 1000
    return float(np.median(lat)), float(np.percentile(lat, 99))


def fuzz() -> tuple[int, int, bool]:
    rng = np.random.default_rng(7)
    chunks, bodies = [], []
    for i in range(100_000):
        chunks.append(rng.integers(0, 256, int(rng.integers(0, 16)), dtype=np.uint8).tobytes())
        if i % 4 == 0:
            body = JointSample(i, i, (float(i % 90),) * 6).body()
            bodies.append(body)
            chunks.append(encode(body))
    stream = b"".join(chunks)
    a = SentenceAssembler()
    out = []
    cuts = rng.integers(1, 300, len(stream) // 50)
    pos = 0
    for c in cuts:
        out += a.feed(stream[pos : pos + int(c)])
        pos += int(c)
    out += a.feed(stream[pos:])
    return len(bodies), len(out), out == bodies


def _sim(*args):
    proc = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", "sim-controller", "--robot", "plain", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    proc.stdout.readline()
    return proc


def replug_pty(tmp: Path) -> float:
    link_path = tmp / "bench-controller"
    proc = _sim("--pty", "--link", str(link_path), "--reboot-after", "1.0", "--reboot-downtime", "0.5")
    link = ControllerLink(str(link_path), rate_hz=100).start(wait_open=True)
    link.wait_for_samples(20, 5)
    proc.stdout.readline()  # the new device after the reboot
    back = time.monotonic()
    before = link.stats.samples
    while link.stats.samples <= before and time.monotonic() - back < 10:
        time.sleep(0.002)
    resumed = time.monotonic() - back
    link.close()
    proc.terminate()
    proc.wait()
    return resumed


def replug_tcp() -> float:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = _sim("--tcp", str(port))
    link = ControllerLink(f"socket://127.0.0.1:{port}", rate_hz=100).start(wait_open=True)
    link.wait_for_samples(20, 5)
    proc.terminate()
    proc.wait()
    while link.state is not LinkState.DOWN:
        time.sleep(0.005)
    proc = _sim("--tcp", str(port))
    back = time.monotonic()
    before = link.stats.samples
    while link.stats.samples <= before and time.monotonic() - back < 10:
        time.sleep(0.002)
    resumed = time.monotonic() - back
    link.close()
    proc.terminate()
    proc.wait()
    return resumed


def main() -> str:
    import tempfile

    rate, n = parse_rate()
    med, p99 = latency()
    sent, got, exact = fuzz()
    with tempfile.TemporaryDirectory() as tmp:
        pty_resume = replug_pty(Path(tmp))
    tcp_resume = replug_tcp()
    lines = [
        "# Controller link benchmarks",
        "",
        f"Generated by `make bench` (bench/link_bench.py) on {platform.machine()}, Python {platform.python_version()}, "
        f"{os.cpu_count()} cores.",
        "",
        "| measure | result | target |",
        "|---|---|---|",
        f"| sentences parsed from a pty, driver end to end ({n} JNT sentences) | {rate:,.0f} /s | >= 2 000 /s |",
        f"| last byte written -> sample callback, median | {med:.2f} ms | <= 5 ms |",
        f"| last byte written -> sample callback, 99th percentile | {p99:.2f} ms | <= 20 ms |",
        f"| fuzz: 100 000 garbage chunks, {sent} valid sentences | {got} delivered, "
        f"{'exactly those, in order' if exact else 'MISMATCH'} | every one once, in order, nothing invented |",
        f"| pty controller rebooted: samples resume after it is back | {pty_resume:.2f} s | <= 2 s |",
        f"| TCP server restarted: samples resume after it is back | {tcp_resume:.2f} s | <= 2 s |",
        "",
    ]
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text("\n".join(lines))
    return str(OUT)


if __name__ == "__main__":
    print(main())
