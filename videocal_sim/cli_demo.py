"""``videocal demo``: the whole calibration driven through the real window, with a PNG after
each step and ``report.json`` in the output folder. Registered by the simulator's package
(entry point ``videocal.commands``: ``demo``)."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from app.cli.options import bounded_float, resolved_path
from calib_core.errors import VideocalError


HELP = "drive the window through a whole calibration on the simulated cell, writing screenshots and report.json"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--out", type=resolved_path, default=Path("out/demo"), help="folder for the screenshots and report.json"
    )
    parser.add_argument("--offscreen", action="store_true", help="no display needed: Qt's offscreen platform")
    parser.add_argument(
        "--scale", type=bounded_float(0.1, 2.0), default=1.0, help="camera resolution relative to the camera file's"
    )
    parser.add_argument(
        "--workcell", type=resolved_path, default=None, help="the cell to calibrate in (default: the bundled one)"
    )
    parser.add_argument("--location", help="the task location to calibrate at (default: the cell's first)")
    parser.add_argument(
        "--cold",
        action="store_true",
        help="the cold cell: intrinsics, robot and mounting, camera to tool, then one look at the task location, each "
        "beside the truth (no window)",
    )
    parser.add_argument(
        "--site",
        choices=("sim", "ros2", "gige", "ur"),
        default="sim",
        help="how the window reaches the simulated cell: videocal's own link and the in-process camera (default); ROS "
        "2 "
        "(a simulated ros2_control arm and a camera topic on Cyclone DDS, on ROS_DOMAIN_ID when set, else a private "
        "domain 71-100); or gige (the camera "
        "served as a GigE Vision camera on the loopback interface, read through Aravis); or ur (the robot a simulated "
        "Universal "
        "Robots controller: RTDE through ur_rtde, moves as URScript)",
    )
    parser.add_argument(
        "--link-delay-ms",
        type=bounded_float(0.0, 5000.0),
        default=0.0,
        metavar="MS",
        help="put the controller far away: this one-way delay, +-30 %% jitter, 1 %% lost, on videocal's link (--site "
        "sim: a TCP "
        "delay line) or ROS 2's (--site ros2: the arm in a network namespace of its own, every DDS packet delayed; "
        "needs root); the frames follow the link's samples, as a gripper camera's would",
    )
    parser.add_argument(
        "--look",
        choices=("plain", "workshop"),
        default="plain",
        help="how the simulated camera's images look: plain (the parts as their CAD, one key light; default) or "
        "workshop "
        "(the parts printed and up to a millimetre off their CAD, three lamps casting shadows, highlights, a noisier "
        "and "
        "softer camera: what a real camera shows)",
    )
    parser.add_argument(
        "--method",
        choices=("find-points", "picks", "edges"),
        default="find-points",
        help="how each look is made: Find points and Accept all (default), the operator's picks by hand, or Find "
        "points and Calibrate on edges",
    )


def run(args: argparse.Namespace) -> int:
    if args.out.exists() and not args.out.is_dir():
        raise VideocalError(
            f"{args.out}: --out names a file; the demo writes its screenshots and report.json into a folder"
        )
    if args.cold:
        return _cold(args)
    if args.offscreen:
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    from videocal_sim.demo_operator import run_demo

    from calib_core.workcell import DEFAULT_WORKCELL

    report = run_demo(
        args.out,
        scale=args.scale,
        workcell=args.workcell or DEFAULT_WORKCELL,
        location=args.location,
        method=args.method,
        site_kind=args.site,
        link_delay_ms=args.link_delay_ms,
        look=args.look,
    )
    print(
        json.dumps(
            {
                k: report[k]
                for k in (
                    "site",
                    "camera_look",
                    "status",
                    "pairs",
                    "rms_px",
                    "corrected_tcp_error_mm",
                    "corrected_tcp_error_deg",
                    "uncorrected_tcp_error_mm",
                )
            },
            indent=2,
        )
    )
    print(f"screenshots and report.json in {args.out}")
    # The window, its link and its camera are closed and report.json is written: leave without the interpreter's final
    # clean-up, which tore down Qt and the connectors' native threads in any order (a good run once ended with exit 134,
    # "QThread: Destroyed while thread is still running").
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


def _cold(args: argparse.Namespace) -> int:
    import sys

    from calib_core.atomic_file import atomic_write_text
    from calib_core.robot_calibration.report import save_robot_calibration
    from videocal_sim.cold_robot_calibration import calibrate_cold_cell
    from videocal_sim.cold_task_look import look_at_task

    if args.workcell is not None:
        raise VideocalError("demo --cold runs on the bundled cell (its cold twin is built from it)")
    args.out.mkdir(parents=True, exist_ok=True)

    def say(text):
        print(text, file=sys.stderr)

    from calib_core.workcell import load_workcell

    tasks = list(load_workcell().task_locations)
    look_task = args.location or tasks[0]
    if look_task not in tasks:
        raise VideocalError(f"the bundled cell has no task location {look_task!r}; task locations: {', '.join(tasks)}")
    # The tool is measured at the other fixtures, so the look's task location is a check of its own.
    run = calibrate_cold_cell(
        40,
        0,
        grasp_tasks=[t for t in tasks if t != look_task] or tasks,
        progress=lambda k, n: print(f"\rboard view {k} of {n}", end="" if k < n else "\n", file=sys.stderr),
        say=say,
    )
    save_robot_calibration(args.out, run.result, run.nominal_robot, robot=run.robot, tool=run.tool)
    say("looking at the task location with the calibrated model...")
    from videocal_sim.cold_cell import cold_test_bed

    bed, _ = cold_test_bed(seed=0)
    from calib_core.calibration.look_fusion import tcp_covariance_from_camera
    from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM

    def model_covariance(q):
        return tcp_covariance_from_camera(run.result.pose_covariance(q), run.robot.fk(q, "camera"), run.tool.tcp2cam)

    look = look_at_task(
        bed,
        run.robot,
        run.result.intrinsics,
        look_task,
        model_covariance=model_covariance,
        placement_sigma_mm=SURVEY_SIGMA_MM,
        from_where="task",
        tool=run.tool,
    )
    i = run.intrinsics
    report = {
        "cell": "cold (videocal_sim/cold_cell.py, seed 0)",
        "steps": {
            "1_intrinsics": {
                "views": len(i.used),
                "rms_px": round(i.rms_px, 4),
                "error_against_truth_px": run.score["intrinsics_error_px"],
            },
            "2_robot_and_mounting": {
                "board_views": run.board_views,
                "cell_views": run.cell_views,
                "identified": len(run.result.observability.identified),
                "of": len(run.result.names),
                "rms_px": round(run.result.rms_px, 4),
                "seconds": round(run.result.seconds, 2),
                "camera_in_base_frame_mm_deg": run.score["camera_in_base_frame_mm_deg"],
                "camera_nominal_model_mm_deg": run.score["camera_nominal_model_mm_deg"],
            },
            "3_camera_to_tool": {
                "grasps": sorted(run.tool.per_grasp),
                "seen_by_the_camera": run.tool.seen_grasps,
                "spread_mm": round(run.tool.spread_mm, 4),
                "tcp_in_base_frame_mm_deg": run.score["tcp_in_base_frame_mm_deg"],
                "tcp_nominal_model_mm_deg": run.score["tcp_nominal_model_mm_deg"],
            },
            "4_task_location": look,
        },
        "measured": [
            "intrinsics",
            "the identified robot parameters",
            "the components' poses",
            "the TCP in the camera frame (each grasp: the held fixture's pose in the camera's frame)",
            "the look at the task",
        ],
        "from_the_model": [
            "the parameters the observability report leaves unidentified",
            "the survey (0.05 mm 1-sigma; weighs the model against the look)",
            "each grasp's place on its fixture (the workcell file)",
            "the fingers' centring on the pin (0.01 mm 1-sigma)",
        ],
        "rejected": run.rejected,
    }
    atomic_write_text(args.out / "report.json", json.dumps(report, indent=2))
    print(json.dumps(report["steps"], indent=2))
    print(f"report.json, robot_calibration.yaml and the calibrated URDF in {args.out}")
    return 0
