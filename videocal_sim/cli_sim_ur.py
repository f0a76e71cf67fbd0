"""``videocal sim-ur``: a simulated Universal Robots controller (RTDE, URScript, dashboard) for a cell's robot on a
loopback address. Prints ``ready`` once it serves; runs until SIGTERM or Ctrl-C. Commands on stdin, for tests and
demos: ``protective-stop``, ``local``, ``remote``, ``speed F`` (the speed slider, 0..1)."""

from __future__ import annotations

import argparse
import signal
import sys
import threading

from app.cli.options import resolved_path

HELP = (
    "serve a cell's robot as a simulated Universal Robots controller (RTDE on 30004, URScript on 30002, dashboard "
    "on 29999)"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--host",
        default="127.0.0.2",
        help="the loopback address to serve on (default 127.0.0.2; the ports are UR's fixed ones)",
    )
    parser.add_argument(
        "--workcell",
        type=resolved_path,
        default=None,
        help="the cell whose robot it is (6 joints; default: the bundled one)",
    )
    parser.add_argument(
        "--joints", help="initial joints in URDF order, deg, separated by commas (default: the cell's home)"
    )


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from calib_core.errors import VideocalError
    from calib_core.operator.cell import Cell
    from calib_core.workcell import DEFAULT_WORKCELL
    from videocal_sim.sim_process import joints_option
    from videocal_sim.ur_controller import SimulatedURController

    cell = Cell.open(args.workcell or DEFAULT_WORKCELL)
    robot = cell.robot
    if robot.n_joints != 6 or any(u != "deg" for u in robot.joint_units):
        raise VideocalError(
            f"a UR controller drives 6 revolute joints; {cell.workcell.path}'s robot has {robot.n_joints} "
            f"({', '.join(robot.joint_units)})"
        )
    initial = joints_option(args.joints, 6, cell.home_joints)
    lower = np.radians(np.where(np.isfinite(robot.lower_limits_deg), robot.lower_limits_deg, -360.0))
    upper = np.radians(np.where(np.isfinite(robot.upper_limits_deg), robot.upper_limits_deg, 360.0))
    try:
        sim = SimulatedURController(
            np.radians(initial),
            host=args.host,
            lower_rad=lower,
            upper_rad=upper,
            log=lambda text: print(text, file=sys.stderr, flush=True),
        ).start()
    except OSError as exc:
        raise VideocalError(f"cannot serve on {args.host}: {exc}") from None
    done = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: done.set())

    def commands() -> None:
        for line in sys.stdin:
            word, _, value = line.strip().partition(" ")
            if word == "protective-stop":
                sim.protective_stop()
            elif word in ("local", "remote"):
                sim.remote_control = word == "remote"
            elif word == "speed":
                sim.speed_slider = min(max(float(value), 0.0), 1.0)
            print(f"ok {word}", flush=True)

    threading.Thread(target=commands, daemon=True).start()
    print("ready", flush=True)
    done.wait()
    sim.close()
    return 0
