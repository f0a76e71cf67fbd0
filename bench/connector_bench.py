"""Connectors, each beside a bare client of the same library in the same run. Writes
docs/benchmarks/connectors.md.

- ROS 2 joint states at 500 Hz from ``videocal sim-ros2`` (another process): samples per second delivered by the
  ``ros2://`` connector and lost samples, beside a bare cyclonedds reader; latency from the header stamp to the
  connector's delivery (same machine, same clock).
- UR RTDE at 500 Hz from ``videocal sim-ur`` (another process): samples per second through the ``ur-rtde://``
  connector beside ur_rtde's ``RTDEReceiveInterface`` polled bare.
- A 1280 x 960 RGB8 GigE Vision stream (Aravis's fake GigE Vision camera in another process): frames per second and
  frame age at the ``aravis://`` connector beside Aravis's stream popped bare.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from calib_core.workcell import DEFAULT_WORKCELL

OUT = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "connectors.md"
SECONDS = 8.0


def _start(args, env=None):
    process = subprocess.Popen(
        [sys.executable, "-m", "app.cli.main", *args],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env={**os.environ, **(env or {})},
    )
    assert process.stdout.readline().strip() == "ready"
    return process


def _context(rate_hz):
    from calib_core.connectors.controller import ControllerContext
    from calib_core.operator.cell import Cell

    cell = Cell.open(DEFAULT_WORKCELL)
    return ControllerContext.of(cell.robot, cell.joint_map, rate_hz)


def _collect(link, seconds):
    got = []
    link.sample_received.connect(lambda s: got.append((time.time_ns(), s.sample.t_ms)))
    link.start()
    deadline = time.monotonic() + 20
    while not got and time.monotonic() < deadline:
        time.sleep(0.01)
    got.clear()
    time.sleep(seconds)
    samples = list(got)
    link.close()
    return samples


def ros2_joints() -> dict:
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    from calib_core.connectors.registry import open_controller
    from calib_core.ros2 import messages as msg
    from calib_core.ros2.participant import participant
    from calib_core.ros2.taker import Taker
    from calib_core.ros2.wire import default_qos

    domain = 90 + os.getpid() % 40
    arm = _start(["sim-ros2", "--rate", "500", "--domain", str(domain)])
    try:
        samples = _collect(open_controller(f"ros2:///joint_states?domain={domain}", _context(500.0)), SECONDS)
        dp = participant(domain)
        taker = Taker(DataReader(dp, Topic(dp, "rt/joint_states", msg.JointState), qos=default_qos(100)))
        bare = []
        end = time.monotonic() + 2.0
        while time.monotonic() < end:  # let it match
            taker.take(100, 0.02)
        end = time.monotonic() + SECONDS
        while time.monotonic() < end:
            for m in taker.take(100, 0.02):
                bare.append((time.time_ns(), m.header.stamp.ns() // 1_000_000))
    finally:
        arm.terminate()
        arm.wait(10)

    def figures(rows):
        stamps = np.array([t for _, t in rows])
        span_s = (stamps[-1] - stamps[0]) / 1000.0
        latency_ms = np.array([(arrival / 1e6) - t for arrival, t in rows])
        return {
            "rate": (len(rows) - 1) / span_s,
            "lost": max(0, int(round(span_s * 500)) + 1 - len(rows)),
            "p50": float(np.percentile(latency_ms, 50)),
            "p99": float(np.percentile(latency_ms, 99)),
        }

    return {"connector": figures(samples), "bare": figures(bare)}


def rtde_joints() -> dict:
    import rtde_receive

    from calib_core.connectors.registry import open_controller

    host = f"127.0.{os.getpid() % 200 + 20}.9"
    sim = _start(["sim-ur", "--host", host, "--joints", "0,10,-30,0,45,0"])
    try:
        samples = _collect(open_controller(f"ur-rtde://{host}?rate_hz=500", _context(500.0)), SECONDS)
        receive = rtde_receive.RTDEReceiveInterface(host, 500.0, ["timestamp", "actual_q"])
        stamps = set()
        end = time.monotonic() + SECONDS
        while time.monotonic() < end:
            stamps.add(receive.getTimestamp())
            time.sleep(0.0002)
        receive.disconnect()
    finally:
        sim.terminate()
        sim.wait(10)
    connector_stamps = sorted({t for _, t in samples})
    return {"connector": len(connector_stamps) / SECONDS, "bare": len(stamps) / SECONDS}


def _serve_gige():
    code = (
        "import numpy as np, signal, threading\n"
        "from videocal_sim.gige_camera import SimulatedGigECamera\n"
        "image = np.random.default_rng(0).integers(0, 255, (960, 1280, 3), dtype=np.uint8)\n"
        "camera = SimulatedGigECamera(lambda: image)\n"
        "print('ready', flush=True)\n"
        "done = threading.Event(); signal.signal(signal.SIGTERM, lambda *_: done.set()); done.wait()\n"
    )
    process = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True
    )
    assert process.stdout.readline().strip() == "ready"
    return process


def gige_stream() -> dict:
    from calib_core.connectors.registry import open_camera
    from calib_core.gige.aravis_lib import aravis

    server = _serve_gige()
    try:
        camera = open_camera("aravis://127.0.0.1?pixel_format=RGB8&width=1280&height=960")
        camera.read()
        ages, count, start = [], 0, time.monotonic()
        while time.monotonic() - start < SECONDS:
            frame = camera.read()
            ages.append((time.monotonic() - frame.t_host_s) * 1000)
            count += 1
        connector = {
            "fps": count / (time.monotonic() - start),
            "age_p50": float(np.median(ages)),
            "age_p99": float(np.percentile(ages, 99)),
            "camera_fps": camera.fps,
            "skipped": camera.skipped,
        }
        camera.close()
        Aravis = aravis()
        cam = Aravis.Camera.new("127.0.0.1")
        cam.set_pixel_format_from_string("RGB8")
        cam.set_region(0, 0, 1280, 960)
        stream = cam.create_stream(None, None)
        for _ in range(8):
            stream.push_buffer(Aravis.Buffer.new_allocate(cam.get_payload()))
        cam.start_acquisition()
        count, start = 0, time.monotonic()
        while time.monotonic() - start < SECONDS:
            buffer = stream.timeout_pop_buffer(2_000_000)
            if buffer is not None:
                count += buffer.get_status() == Aravis.BufferStatus.SUCCESS
                stream.push_buffer(buffer)
        cam.stop_acquisition()
        bare = count / (time.monotonic() - start)
    finally:
        server.terminate()
        server.wait(10)
    return {"connector": connector, "bare": bare}


def demo_through(site: str) -> dict:
    """``videocal demo --offscreen --site SITE``: the whole calibration through that connector; its report's corrected
    tool error (scored against the simulator's truth) and the run's wall time."""
    import json
    import tempfile

    with tempfile.TemporaryDirectory() as out:
        began = time.monotonic()
        run = subprocess.run(
            [sys.executable, "-m", "app.cli.main", "demo", "--offscreen", "--site", site, "--out", out],
            capture_output=True,
            text=True,
            timeout=1200,
            env={**os.environ, "QT_QPA_PLATFORM": "offscreen"},
        )
        seconds = time.monotonic() - began
        if run.returncode != 0:
            return {"site": site, "failed": (run.stderr.strip().splitlines() or ["no output"])[-1], "seconds": seconds}
        report = json.loads((Path(out) / "report.json").read_text())
    return {
        "site": site,
        "seconds": seconds,
        "status": report.get("status"),
        "error_mm": report.get("corrected_tcp_error_mm"),
        "error_deg": report.get("corrected_tcp_error_deg"),
        "before_mm": report.get("uncorrected_tcp_error_mm"),
        "via": report.get("site"),
    }


def main() -> str:
    ros, rtde, gige = ros2_joints(), rtde_joints(), gige_stream()
    demos = [demo_through(site) for site in ("sim", "ros2", "ur", "gige")]
    c, b = ros["connector"], ros["bare"]
    g = gige["connector"]
    lines = [
        "# Connectors",
        "",
        f"`make bench` on {platform.machine()}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}; the other side in "
        "another process on the same "
        f"machine; {SECONDS:g} s per figure. Each connector beside a bare client of the same library in the same run.",
        "",
        "| what | connector | bare client | ratio |",
        "|---|---|---|---|",
        f"| ROS 2 `/joint_states` at 500 Hz: samples/s delivered | {c['rate']:.0f} | {b['rate']:.0f} (cyclonedds "
        f"reader) | {c['rate'] / b['rate']:.2f} |",
        f"| ROS 2: samples lost (from the stamps' span; +-1: stamps are whole ms) | {c['lost']} | {b['lost']} | |",
        f"| ROS 2: stamp to delivery, median / 99th percentile | {c['p50']:.2f} / {c['p99']:.2f} ms | {b['p50']:.2f} / "
        f"{b['p99']:.2f} ms | {c['p50'] / max(b['p50'], 1e-6):.2f} |",
        f"| UR RTDE at 500 Hz: controller samples/s seen | {rtde['connector']:.0f} | {rtde['bare']:.0f} (ur_rtde "
        f"polled) | {rtde['connector'] / rtde['bare']:.2f} |",
        f"| GigE Vision 1280 x 960 RGB8: frames/s at the connector | {g['fps']:.1f} | {gige['bare']:.1f} (Aravis "
        f"stream) | {g['fps'] / gige['bare']:.2f} |",
        f"| GigE: frame age at the connector, median / 99th percentile | {g['age_p50']:.1f} / {g['age_p99']:.1f} ms | "
        "| |",
        "",
        "Notes: the simulated UR controller and the fake GigE camera are Python/Aravis programs on the same two cores; "
        "their own rates bound the figures (the bare clients show them). The fake GigE camera's frame rate: "
        f"{g['camera_fps']:.0f} fps; "
        f"frames passed over for a newer one at the connector: {g['skipped']}.",
        "",
        "## The whole calibration through each connector",
        "",
        "`videocal demo --offscreen --site SITE`: the window drives the simulated cell through that connector (`sim`: "
        "videocal's own "
        "link and the in-process camera, today's default). The error is the corrected tool's distance from the task "
        "location, "
        "scored against the simulator's truth, which nothing in the run reads.",
        "",
        "| site | reached through | status | corrected tool error | before | run time | ratio to `sim` |",
        "|---|---|---|---|---|---|---|",
    ]
    base = next((d["seconds"] for d in demos if d["site"] == "sim" and "failed" not in d), None)
    for d in demos:
        if "failed" in d:
            lines.append(f"| `{d['site']}` | | FAILED: {d['failed']} | | | {d['seconds']:.0f} s | |")
            continue
        ratio = f"{d['seconds'] / base:.2f}" if base else ""
        lines.append(
            f"| `{d['site']}` | {d['via']} | {d['status']} | {d['error_mm']:.3f} mm, {d['error_deg']:.3f} deg | "
            f"{d['before_mm']:.2f} mm | "
            f"{d['seconds']:.0f} s | {ratio} |"
        )
    lines.append("")
    OUT.write_text("\n".join(lines))
    return str(OUT)


if __name__ == "__main__":
    print(main())
