"""A far controller: the operator's time per look through a delay line of 0, 0.3 and
1.5 s one way (+-30 % jitter, 1 % of the chunks lost once), videocal's own protocol to the controller simulator in
another process. Writes docs/benchmarks/remote.md.

A look, as the operator waits for it: Go pressed (the move sent) -> the controller's DON -> the joint history at the
workstation shows the robot still for the settle rule's hold time (stamped by the controller's clock), so a frame
of that time can be picked on. Also: the handshake's time, the measured one-way delay, the moves sent and the
moves that reached the controller (the delay line's tap), dead-man stops. The near link (0 s) is the peer: ratios
are against it, in the same run.
"""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "remote.md"
DELAYS_S = (0.0, 0.3, 1.5)
LOOKS = 4
POSES = ([20.0, -10.0, 15.0, 0.0, 30.0, 0.0], [-20.0, 10.0, -15.0, 5.0, -30.0, 10.0])


def _settled_after(history, clock_now, since_s: float, timeout_s: float) -> float | None:
    """Poll until the history says the robot was still at its newest sample (newer than ``since_s``)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        newest = history.latest_s
        if newest is not None and newest > since_s and history.stillness(newest).settled:
            return clock_now()
        time.sleep(0.005)
    return None


def one_delay(one_way_s: float) -> dict:
    from calib_core.link.driver import ControllerLink
    from calib_core.link.joint_history import ControllerClock, JointHistory
    from calib_core.link.workstation_auth import AuthState
    from videocal_sim.delay_line import DelayLine, LinkWeather

    sim = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "sim-controller",
            "--tcp",
            "0",
            "--robot",
            "plain",
            "--joints",
            "0,0,0,0,0,0",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    port = int(re.search(r":(\d+)", sim.stdout.readline()).group(1))
    seen: list[str] = []
    tap = lambda direction, data: (
        seen.extend(re.findall(r"MVJ,([\w.]+),", data.decode(errors="replace"))) if direction == "up" else None
    )
    line = DelayLine(("127.0.0.1", 0), ("127.0.0.1", port), LinkWeather(one_way_s, 0.3, 0.01), seed=11, tap=tap).start()
    history, clock = JointHistory(), ControllerClock()
    looks, sent, stops = [], [], 0
    try:
        t0 = time.monotonic()
        link = ControllerLink(f"socket://127.0.0.1:{line.address[1]}", rate_hz=50, deadman_ms=1000)
        link.sample_received.connect(
            lambda s: history.add(clock.stamp(s.t_host_s, s.sample.t_ms / 1000.0), np.asarray(s.joints_deg))
        )
        link.start()
        ready = link._auth.wait_settled(60.0) is AuthState.READY
        handshake_s = time.monotonic() - t0
        for k in range(LOOKS if ready else 0):
            go = time.monotonic()
            handle = link.move_joints(POSES[k % 2], timeout_s=120.0)
            sent.append(handle.id)
            try:
                handle.wait(120.0)
            except Exception as exc:  # a refusal (dead-man) is counted, not fatal to the bench
                stops += "DEADMAN" in str(exc)
                continue
            done = _settled_after(history, time.monotonic, go, 60.0)
            if done is not None:
                looks.append(done - go)
        delay = link.delay_s
        link.close()
    finally:
        line.close()
        sim.terminate()
        sim.wait(10)
    return {
        "one_way": one_way_s,
        "ready": ready,
        "handshake_s": handshake_s,
        "looks": looks,
        "delay_s": delay,
        "sent": len(sent),
        "seen": len(seen),
        "duplicates": len(seen) - len(set(seen)),
        "stops": stops,
        "late": line.stats.late,
    }


def window_demo(one_way_s: float, site: str = "sim") -> dict:
    """The whole calibration through the window (``videocal demo --site SITE --link-delay-ms``): Go pressed -> a frame
    the core accepts for picks, per look, and the corrected tool's error (scored against the simulator's truth)."""
    import json
    import tempfile

    with tempfile.TemporaryDirectory(prefix="videocal-remote-bench-") as folder:
        run = subprocess.run(
            [
                sys.executable,
                "-m",
                "app.cli.main",
                "demo",
                "--offscreen",
                "--scale",
                "0.5",
                "--out",
                folder,
                "--site",
                site,
                "--link-delay-ms",
                f"{1000 * one_way_s:g}",
            ],
            capture_output=True,
            text=True,
            timeout=900,
        )
        if run.returncode != 0:
            return {"one_way": one_way_s, "failed": run.stderr.strip().splitlines()[-1]}
        report = json.loads((Path(folder) / "report.json").read_text())
    return {
        "one_way": one_way_s,
        "looks": report["link"]["go_to_settled_frame_s"],
        "measured": report["link"]["measured_one_way_s"],
        "error_mm": report["corrected_tcp_error_mm"],
        "status": report["status"],
    }


_FAKE_CAMERA = (
    "import gi, time\ngi.require_version('Aravis', '0.8')\nfrom gi.repository import Aravis\n"
    "camera = Aravis.GvFakeCamera.new('vcfar0', 'FAR01')\nprint('serving' if camera.is_running() else 'failed', "
    "flush=True)\ntime.sleep(900)\n"
)


def gige_far(one_way_s: float, seconds: float = 20.0) -> dict:
    """Aravis's own fake GigE Vision camera on the robot's side of the far network (its test pattern), read here through
    the ``aravis://`` connector: how long it takes to open, and frames per second after."""
    from calib_core.connectors.registry import open_camera
    from videocal_sim.delay_line import LinkWeather
    from videocal_sim.far_network import FarNetwork

    with FarNetwork(LinkWeather(one_way_s, 0.3, 0.01), seed=7) as net:
        camera = subprocess.Popen(
            net.far_command([sys.executable, "-c", _FAKE_CAMERA]), stdout=subprocess.PIPE, text=True
        )
        try:
            if camera.stdout.readline().strip() != "serving":
                return {"one_way": one_way_s, "failed": "the fake camera did not serve"}
            t0 = time.monotonic()
            try:
                source = open_camera(f"aravis://{net.far_ip}?timeout_s=10")
            except Exception as exc:  # what the connector says is the figure
                return {"one_way": one_way_s, "failed": str(exc), "after_s": time.monotonic() - t0}
            opened_s = time.monotonic() - t0
            frames, t1 = 0, time.monotonic()
            while time.monotonic() - t1 < seconds:
                try:
                    frames += source.read() is not None
                except Exception:
                    pass
            source.close()
            return {"one_way": one_way_s, "opened_s": opened_s, "fps": frames / seconds}
        finally:
            camera.kill()
            camera.wait()


def _demo_table(demos: list[dict]) -> list[str]:
    """The window demos' table, ratios against the first row (0 s)."""
    lines = [
        "| one-way delay | Go -> usable frame, per look | median | ratio to 0 s | measured one-way | corrected tool "
        "error | status |",
        "|---|---|---|---|---|---|---|",
    ]
    near = np.median(demos[0].get("looks") or [np.nan])
    for d in demos:
        if "failed" in d:
            lines.append(f"| {d['one_way']:g} s | FAILED: {d['failed']} | | | | | |")
            continue
        median = np.median(d["looks"])
        lines.append(
            f"| {d['one_way']:g} s | {', '.join(f'{v:.1f} s' for v in d['looks'])} | {median:.1f} s | "
            f"{median / near:.1f} | "
            f"{d['measured'] or 0:.2f} s | {d['error_mm']:.3f} mm | {d['status']} |"
        )
    return lines


def main() -> str:
    rows = [one_delay(d) for d in DELAYS_S]
    demos = [window_demo(d) for d in DELAYS_S]
    from videocal_sim.far_network import why_not_available

    no_far_network = why_not_available()
    ros2 = [] if no_far_network else [window_demo(d, "ros2") for d in DELAYS_S]
    gige = [] if no_far_network else [gige_far(d) for d in DELAYS_S]
    peer = np.median(rows[0]["looks"]) if rows[0]["looks"] else float("nan")
    lines = [
        "# A far controller",
        "",
        f"`make bench` on {platform.machine()}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}. videocal's own "
        "protocol through "
        "`videocal_sim/delay_line.py` (one-way delay, +-30 % jitter, 1 % of the chunks lost once and delivered a round "
        "trip "
        "late, as TCP does) to the controller simulator in another process. A look: Go -> DON -> the joint history at "
        "the "
        f"workstation shows the robot still for the settle rule's hold; {LOOKS} looks between two poses 40-60 deg "
        "apart. "
        "Peer: the same program through the line at 0 s.",
        "",
        "| one-way delay | handshake | measured one-way | time per look (median) | ratio to 0 s | moves sent / "
        "reaching the controller | sent twice | dead-man stops | chunks lost once |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        look = np.median(r["looks"]) if r["looks"] else float("nan")
        measured = "-" if r["delay_s"] is None else f"{r['delay_s']:.2f} s"
        lines.append(
            f"| {r['one_way']:g} s | {r['handshake_s']:.1f} s{'' if r['ready'] else ' (FAILED)'} | {measured} | "
            f"{look:.2f} s ({len(r['looks'])}/{LOOKS}) | "
            f"{look / peer:.1f} | {r['sent']} / {r['seen']} | {r['duplicates']} | {r['stops']} | {r['late']} |"
        )
    lines += [
        "",
        "## Through the window",
        "",
        "`videocal demo --offscreen --scale 0.5 --link-delay-ms MS` (the same delay line on the controller link; the "
        "simulated "
        "camera follows the joints the link delivers, so its frames come as late as the samples, as a gripper camera's "
        "would). A look: Go pressed -> a frame the core accepts for picks (the settle rule widened by the link's "
        "spread of "
        "delays). The corrected tool's error is scored against the simulator's truth.",
        "",
        *_demo_table(demos),
    ]
    lines += ["", "## ROS 2 through the window", ""]
    if no_far_network:
        lines.append(f"Not measured on this machine: {no_far_network}.")
    else:
        lines += [
            "`videocal demo --offscreen --scale 0.5 --site ros2 --link-delay-ms MS`: the simulated ros2_control arm in "
            "a network "
            "namespace of its own behind `videocal_sim/far_network.py`, every DDS packet to and from it delayed (one "
            "way, +-30 %, in "
            "order) and 1 % dropped; the camera's frames follow the joint states as they arrive and carry their "
            "stamps. At 0 s there "
            "is no relay: DDS on the loopback (the peer). The measured one-way delay is the joint states' arrival "
            "minus their "
            "stamps (a FIFO path with +-30 % jitter delivers near its upper end).",
            "",
            *_demo_table(ros2),
        ]
    lines += ["", "## A GigE Vision camera through the far network", ""]
    if no_far_network:
        lines.append(f"Not measured on this machine: {no_far_network}.")
    else:
        lines += [
            "Aravis's own fake GigE Vision camera (its test pattern, 25 fps) on the robot's side of "
            "`videocal_sim/far_network.py` "
            "(one way, +-30 %, 1 % of the frames dropped), read through `aravis://` with Aravis 0.8 on this side. GigE "
            "Vision is a "
            "LAN protocol: Aravis waits a fixed time for each control answer (no setting for it in 0.8), so the camera "
            "opens "
            "slowly at 0.3 s and not at all when a round trip outlasts that wait. A frame counts only if all its "
            "packets arrive: "
            "the fake camera resent none of the 1 % lost here, so even at 0 s most frames are incomplete (a real "
            "camera "
            "resends on request). Far away, send the frames on from the robot's side (docs/real-cell.md).",
            "",
            "| one-way delay | opened after | frames/s after | |",
            "|---|---|---|---|",
        ]
        for g in gige:
            if "failed" in g:
                gave_up = f" (gave up after {g['after_s']:.1f} s)" if "after_s" in g else ""
                lines.append(f"| {g['one_way']:g} s | not opened{gave_up} | | {g['failed']} |")
            else:
                lines.append(f"| {g['one_way']:g} s | {g['opened_s']:.1f} s | {g['fps']:.1f} | |")
    lines += [
        "",
        "Measured: every figure, at the workstation (the delay line's weather is the only input; the error is scored "
        "against "
        "the truth). The settle rule asks for stillness over the hold plus the link's spread of delays, and a frame is "
        "judged "
        "only once the samples of its time are in: at 1 % of the segments lost, one of the fifty samples a second is a "
        "round "
        "trip late every two seconds or so, so the spread stays near 4 s (1.5 s +-30 % plus a lost segment's 3.2 s) "
        "and a far "
        "look waits about that twice, on top of the link-level look above. That is the price of never taking a frame "
        "whose "
        "content may be from before the robot stopped. The measured one-way delay is half TCP's "
        "smoothed round trip, which the lost segments' late answers raise above the mean delay. The move's own "
        "duration "
        "(the simulator's trapezoid) and the hold are in every row; what the delay adds is about one round trip (the "
        "move "
        "out, its DON and the samples of the hold back). The handshake is two round trips once the first hello's "
        "answer "
        "is in; at 1.5 s the first try (1.5 s) is over before it, so a second hello goes out and its answer opens the "
        "session.",
        "",
    ]
    OUT.write_text("\n".join(lines))
    return str(OUT)


if __name__ == "__main__":
    print(main())
