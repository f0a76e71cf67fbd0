"""Window targets, measured offscreen (Qt offscreen platform, VTK through OSMesa/llvmpipe on the CPU).
Writes docs/benchmarks/gui.md. On a desktop with a GPU the rendering figures are far higher."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import cv2
import numpy as np

from bench.busy_core import busy_core

OUT = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "gui.md"
OPERATOR_ACTION_S = 1.0
"""A person's time an action (a click, a key, a zoom) in the look time at an operator's pace: a lower bound (see the
table's note)."""


def _settings(path):
    from PySide6.QtCore import QSettings

    settings = QSettings(str(path), QSettings.Format.IniFormat)
    settings.setValue("window/ask_unsaved", False)  # closing a bench window asks nothing
    return settings


def _spin(app, seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        app.processEvents()
        time.sleep(0.002)


def _video_file(path: Path, seconds: float = 6.0) -> None:
    """A 30 fps 1280 x 960 file (MJPG) with moving content."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 30.0, (1280, 960))
    for k in range(int(30 * seconds)):
        img = np.full((960, 1280, 3), 60, np.uint8)
        cv2.circle(img, (100 + 10 * k % 1100, 480), 80, (0, 200, 255), -1)
        writer.write(img)
    writer.release()


def _launch(tmp: Path, tag: str, *args: str) -> tuple[float, float]:
    """Seconds from a fresh ``videocal gui`` process to the loading window, and to the full window."""
    shown_file = tmp / f"shown_{tag}.txt"
    t0 = time.monotonic()
    subprocess.run(
        [sys.executable, "-m", "app.cli.main", "gui", *args, "--screenshot", str(tmp / f"w_{tag}.png")],
        capture_output=True,
        text=True,
        timeout=180,
        env={**os.environ, "VIDEOCAL_REPORT_SHOWN": str(shown_file)},
    )
    shown = float(shown_file.read_text()) - t0 if shown_file.exists() else float("nan")
    ready = (
        float(shown_file.with_suffix(".ready").read_text()) - t0
        if shown_file.with_suffix(".ready").exists()
        else float("nan")
    )
    return shown, ready


def _turn_the_base(wb) -> None:
    """A move long enough to follow (the simulated controllers move at their robot's speeds: a task's approach is
    reached in a fifth of a second): axis 1 turned by up to 150 deg within its limits, the other joints kept."""
    q = np.asarray(wb.joints_deg, dtype=float).copy()
    lo, hi = wb.robot.lower_limits_deg[0], wb.robot.upper_limits_deg[0]
    q[0] = min(q[0] + 150.0, hi - 1.0) if hi - q[0] > q[0] - lo else max(q[0] - 150.0, lo + 1.0)
    wb.moves.move_joints(q, "a turn of the base", confirmed=True)


def _redraws_while_moving(app, wb, view, timeout_s: float = 20.0) -> float:
    """The view's redraws per second from the move's start until the robot arrives (a move that ends in a second
    must not be averaged over the seconds the robot then stands still)."""
    from calib_core.operator.motion import Motion

    t_start = time.monotonic()
    while wb.motion.motion is not Motion.MOVING and time.monotonic() - t_start < 2.0:
        app.processEvents()
        time.sleep(0.002)
    t_moving, redraws_moving = time.monotonic(), view.redraws
    while wb.motion.motion is Motion.MOVING and time.monotonic() - t_start < timeout_s:
        app.processEvents()
        time.sleep(0.002)
    elapsed = time.monotonic() - t_moving
    return (view.redraws - redraws_moving) / elapsed if elapsed > 0.2 else float("nan")


def _overview_fps_following(app, workcell: Path, tmp: Path) -> float:
    """Overview redraws per second while the robot moves to the first task's approach (50 Hz joint stream)."""

    from app.gui.main_window import MainWindow
    from app.gui.workbench import Workbench
    from videocal_sim.sim_site import simulated_cell

    wb = Workbench(*simulated_cell(workcell))
    wb.start_controller()
    win = MainWindow(wb, settings=_settings(tmp / "s_follow.ini"))
    win.resize(1600, 1000)
    win.show()
    _spin(app, 2.0)
    _turn_the_base(wb)
    fps = _redraws_while_moving(app, wb, win.overview)
    win.close()
    return fps


def _preview_ms(workcell: Path | None) -> tuple[float, float, int]:
    """A move's preview (path, limits, singularity, self and cell collisions) for a 60 deg turn of the
    first joint from home: building the collision world once (ms), then each preview (ms, median of 5),
    and the pairs checked."""
    from calib_core.operator.cell import Cell
    from calib_core.operator.core import OperatorCore

    core = OperatorCore(Cell.open(workcell) if workcell is not None else Cell.open())
    t0 = time.perf_counter()
    world = core.cell.collision_world()
    build_ms = 1000 * (time.perf_counter() - t0)
    goal = np.array(core.joints_deg, dtype=float)
    goal[0] += 60.0
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        core.moves.preview_move(goal, "bench")
        times.append(1000 * (time.perf_counter() - t0))
    return build_ms, float(np.median(times)), world.pair_count


def _demo(workcell: Path | None, tmp: Path, tag: str, method: str) -> dict | None:
    args = ["--workcell", str(workcell)] if workcell else []
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "demo",
            "--offscreen",
            *args,
            "--method",
            method,
            "--out",
            str(tmp / tag),
        ],
        capture_output=True,
        text=True,
        timeout=900,
    )
    return json.loads((tmp / tag / "report.json").read_text()) if run.returncode == 0 else {"failed": run.stderr[-300:]}


def _look_times(report: dict | None) -> str:
    """A demo's looks, a settled frame to the correction stored, or why there are none."""
    if not report or "failed" in report:
        return f"failed: {(report or {}).get('failed', 'no report')}"
    proposals = " / ".join(f"{v:.2f} s" for v in report["find_points_proposals_s"])
    return f"{proposals}; {' / '.join(f'{v:.1f} s' for v in report['settled_frame_to_stored_s'])}"


def main() -> str:
    from PySide6.QtWidgets import QApplication

    from videocal_sim.demo_operator import METHODS
    from app.gui.main_window import MainWindow
    from app.gui.warm_up import warm_up_in_background
    from app.gui.workbench import Workbench
    from calib_core.camera.projection import project
    from calib_core.frames import apply, invert
    from videocal_sim.sim_site import simulated_cell
    from calib_core.video.opencv_source import OpenCVSource

    from calib_core.workcell.starter import write_starter_cell
    from tests.vendor_robots import PANDA, SHARE, UR5

    tmp = Path(tempfile.mkdtemp(prefix="videocal-bench-"))
    # 1. Launch to window on screen, as a user starts it (a fresh process).
    launch_s, ready_s = _launch(tmp, "bundled")
    # ... and on a cell of a vendor robot: the UR5 with its DAE meshes (about 96 000 triangles).
    ur5 = write_starter_cell(tmp / "ur5", UR5, [SHARE]).workcell_path
    panda = write_starter_cell(tmp / "panda", PANDA, [SHARE]).workcell_path
    launch_ur5, ready_ur5 = _launch(tmp, "ur5", "--workcell", str(ur5))
    with busy_core():  # another program keeping a core busy: the window's start, and a look by Find points
        launch_loaded, ready_loaded = _launch(tmp, "bundled_loaded")
        demo_loaded = _demo(None, tmp, "demo_loaded", "find-points")

    app = QApplication.instance() or QApplication([])
    wb = Workbench(*simulated_cell())
    wb.start_controller()
    win = MainWindow(wb, settings=_settings(tmp / "s.ini"))
    win.resize(1600, 1000)
    video = tmp / "clip.avi"
    _video_file(
        video, seconds=20.0
    )  # frames until the picks at the end (a pick needs a frame newer than the settled robot)
    win.start_camera(lambda: OpenCVSource(str(video)))
    win.show()
    warm_up_in_background(wb.intrinsics)  # as videocal gui does: the solves below do not wait for the kernels' loading
    _spin(app, 2.0)
    # 2. Camera pane fps on a 30 fps 1280 x 960 file while the overview follows a 50 Hz joint stream and the robot
    # moves.
    shown_frames = []
    win.worker.frame.connect(lambda f: shown_frames.append(time.monotonic()))
    q_start = np.asarray(wb.joints_deg, dtype=float).copy()
    _turn_the_base(wb)
    t_start = time.monotonic()
    overview_fps = _redraws_while_moving(app, wb, win.overview)
    wb.moves.move_joints(q_start, "back", confirmed=True)
    _redraws_while_moving(app, wb, win.overview)
    wb.moves.go_to_task(approach=True)  # where the picks below are made
    _spin(app, max(0.0, 4.0 - (time.monotonic() - t_start)))
    elapsed = time.monotonic() - t_start
    camera_fps = len(shown_frames) / elapsed
    # 3. A joint sample reaching the overview on screen: from its arrival to the redraw that shows it.
    lat = []
    for _ in range(10):
        t_arrive = time.monotonic()
        wb.arm.observe_sample(
            type(
                "S",
                (),
                {
                    "joints_deg": tuple(wb.joints_deg + 0.5),
                    "sample": type("J", (), {"seq": 0, "t_ms": 0})(),
                    "t_host_s": t_arrive,
                },
            )()
        )
        before = win.overview.redraws
        while win.overview.redraws == before and time.monotonic() - t_arrive < 1.0:
            app.processEvents()
            time.sleep(0.001)
        lat.append(time.monotonic() - t_arrive)
    # 4. A pick to the solved overlays on screen: the last 2D pick of a complete set, then Calibrate.
    _spin(app, 3.0)  # the robot arrives at the approach pose
    # the first pick holds the newest frame: wait, as the core does, until that frame's joints are known and still
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline:
        frame = win.camera.last_frame_received
        if frame is not None and wb.observations.stillness(frame).settled:
            break
        app.processEvents()
        time.sleep(0.005)
    fixture = wb.workcell.component("oru_1_fixture")
    true_cam = wb.site.bed.true_cam2world(wb.joints_deg)
    pick_ms, edges_ms = [], []
    for name in (
        "plate_top_left",
        "plate_top_right",
        "plate_bottom_right",
        "plate_bottom_left",
        "pin_tip",
        "boss_top_left",
    ):
        p = apply(fixture.item2world, fixture.features[name])
        wb.picking.pick_model_point("oru_1_fixture", name, p)
        uv = project(apply(invert(true_cam), p[None]), wb.intrinsics)[0]
        t0 = time.perf_counter()
        wb.picking.pick_image_point(uv)  # on the frame the first pick held (the robot has settled at the approach)
        wb.picking.accept_pair()
        if len(wb.session.pairs.usable()) >= 3:
            edges_before = win.camera.edges_drawn
            win.actions.calibrate()
            win.camera.view.repaint()
            pick_ms.append(1000 * (time.perf_counter() - t0))
            while win.camera.edges_drawn == edges_before and time.perf_counter() - t0 < 2.0:
                app.processEvents()
            win.camera.view.repaint()
            edges_ms.append(1000 * (time.perf_counter() - t0))
    win.close()
    overview_ur5 = _overview_fps_following(app, ur5, tmp)
    preview_bundled, preview_ur5 = _preview_ms(None), _preview_ms(ur5)
    # 5. Accuracy: the whole calibration through the window (videocal demo, full size) on the simulated cells,
    # each look made by Find points (the default), by picks by hand, and by Calibrate on edges.
    cells = {
        "bundled (paper's task location)": None,
        "UR5 (videocal new-cell, 6 axes)": ur5,
        "Franka Panda (videocal new-cell, 7 axes)": panda,
    }
    demos = {
        (cell, method): _demo(path, tmp, f"demo_{i}_{method}", method)
        for i, (cell, path) in enumerate(cells.items())
        for method in METHODS
    }
    renderer = (
        "OSMesa (llvmpipe, CPU)"
        if os.environ.get("VTK_DEFAULT_OPENGL_WINDOW") == "vtkOSOpenGLRenderWindow"
        else "the default VTK window class"
    )
    lines = [
        "# Window benchmarks",
        "",
        f"Generated by `make bench` (bench/gui_bench.py) on {platform.machine()}, {os.cpu_count()} cores, Qt platform "
        f"`{os.environ.get('QT_QPA_PLATFORM')}`, VTK through {renderer}. On a desktop with a GPU the rendering figures "
        "are far higher.",
        "",
        "| measure | result | target |",
        "|---|---|---|",
        f"| launch to window on screen (`videocal gui`, fresh process: the loading window) | {launch_s:.2f} s | <= 2 s "
        "|",
        f"| launch to the full window with every pane, the simulator and the link running | {ready_s:.2f} s | <= 5 s |",
        f"| ... with a second process keeping a core busy: to window on screen / to the full window | "
        f"{launch_loaded:.2f} s / {ready_loaded:.2f} s | <= 2 s / <= 5 s |",
        "| ... and a look by Find points (first / second): Find points pressed to its proposals shown; a settled "
        f"frame to the correction stored | {_look_times(demo_loaded)} | <= 2 s to the proposals |",
        f"| UR5 cell (vendor DAE meshes): launch to window on screen | {launch_ur5:.2f} s | <= 3 s |",
        f"| UR5 cell: launch to the full window | {ready_ur5:.2f} s | <= 3 s |",
        f"| UR5 cell: overview redraws while following the 50 Hz joint stream (during the move) | {overview_ur5:.1f} "
        "fps | >= 15 fps |",
        f"| camera pane, 30 fps 1280 x 960 video file, while the robot moves | {camera_fps:.1f} fps | >= 25 fps |",
        f"| overview redraws while following the 50 Hz joint stream (during the move) | {overview_fps:.1f} fps | >= 15 "
        "fps |",
        f"| joint sample to the overview redrawn, median of 10 | {1000 * float(np.median(lat)):.0f} ms | <= 100 ms |",
        "| last pick to the solved overlays drawn (solve, reprojected points and residuals, repaint), median | "
        f"{float(np.median(pick_ms)):.0f} ms | <= 100 ms |",
        "| ... and to the CAD edges from the solved pose drawn over the video (a render of the cell), median | "
        f"{float(np.median(edges_ms)):.0f} ms | |",
        "| move preview of a 60 deg turn (31 poses: limits, singularity, self and cell collisions), bundled cell, "
        f"median | {preview_bundled[1]:.0f} ms ({preview_bundled[2]} pairs; the collision world built once in "
        f"{preview_bundled[0]:.0f} ms) | <= 100 ms |",
        f"| ... UR5 cell (its collision meshes) | {preview_ur5[1]:.0f} ms ({preview_ur5[2]} pairs; built in "
        f"{preview_ur5[0]:.0f} ms) | <= 100 ms |",
    ]
    lines += [
        "",
        "## The whole calibration (`videocal demo`, full size: two looks, each stored)",
        "",
        "TCP error after the stored correction against the test bed's truth (target <= 0.1 mm and 0.1 deg; Find points "
        "and Accept all "
        "no worse than picks by hand). `uncorrected`: the plain model's. `look`: each look's time in the window from a "
        "settled frame to the correction stored (Find points and its dialog, or every pick in both panes, then the "
        "solve and the store; screenshots left out). The picks are scripted clicks, each the instant the last is done: "
        "the window's own time, not an operator's, who takes seconds a pick. `actions`: what each look asked of the "
        "operator, counted as the scripted one does them (a click, a key, a zoom, a box ticked). "
        f"`at an operator's pace`: the look's time plus {OPERATOR_ACTION_S:.0f} s an action, a lower bound for a "
        "person: pointing at a feature to the pixel is about 7 bits (a 3 px target 400 px away), 1.4 s at a mouse's "
        "4.9 bits/s in ISO 9241-9 tests "
        "(MacKenzie and Jusoh, 2001), and a key is quicker.",
        "",
        "| cell | look made by | pairs or edge samples | TCP error after | uncorrected | estimate within 3 sigma (RMS "
        "px) | look, first / second (s) | actions, first / second | at an operator's pace (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for (cell, method), r in demos.items():
        if "failed" in r:
            lines += [f"| {cell} | {method} | the demo failed: {r['failed']!r} | | | | | | |"]
            continue
        used = f"{r['pairs']} pairs" if r["pairs"] else f"{r['edge_samples']} edge samples"
        look_s, actions = r["settled_frame_to_stored_s"], r["operator_actions_per_look"]
        lines += [
            f"| {cell} | {method} | {used} | {r['corrected_tcp_error_mm']:.3f} mm, {r['corrected_tcp_error_deg']:.3f} "
            f"deg | {r['uncorrected_tcp_error_mm']:.2f} mm, "
            f"{r['uncorrected_tcp_error_deg']:.3f} deg | {r['estimate_within_3_sigma']} ({r['rms_px']:.2f}) "
            f"| {' / '.join(f'{s:.1f}' for s in look_s)} "
            f"| {' / '.join(str(a) for a in actions)} "
            f"| {' / '.join(f'{s + OPERATOR_ACTION_S * a:.0f}' for s, a in zip(look_s, actions))} |"
        ]
    lines += [
        "",
        "The paper reached 1.07 mm and 0.64 deg. The demo's true robot has typical joint-offset, link-length and base "
        "errors; the camera looks at the fixture from the task location, then again from the corrected location "
        "(docs/window.md, The correction). The camera mounting is the modelled one (hand-eye exact); the cold cell's "
        "chain is in "
        "robot_calibration.md.",
        "",
        "The UR5 cell's start: 1.5 s of imports, then the cell, its simulated site and the window. Its DAE meshes "
        "cost 0.9 s through Pinocchio's loader on the first start of a machine and 10 ms after (they are kept in the "
        "user's cache folder); before that cache, runs gave 3.0-3.4 s. The overview's frame is about 37 ms of llvmpipe "
        "work whatever its size; since the virtual camera follows a moving robot at half the overview's rate, the "
        "overview keeps 17 fps with the UR5.",
        "",
    ]
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text("\n".join(lines))
    return str(OUT)


if __name__ == "__main__":
    print(main())
