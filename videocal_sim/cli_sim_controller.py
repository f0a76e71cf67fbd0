"""``videocal sim-controller``: a simulated robot controller speaking the wire protocol on a
pty (its path is printed) or a loopback TCP port, with fault injection for tests and demos."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

import numpy as np

from calib_core.errors import VideocalError

HELP = "run a simulated robot controller on a pty or a TCP port"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--pty", action="store_true", help="serve on a new pseudo-terminal and print its path")
    where.add_argument("--tcp", type=int, metavar="PORT", help="serve on 127.0.0.1:PORT (0 picks a free port)")
    parser.add_argument(
        "--link",
        type=Path,
        help="with --pty: keep a symlink at this path to the current pty (stable across --reboot-after)",
    )
    parser.add_argument(
        "--workcell",
        type=Path,
        help="simulate the controller of this cell's robot: its joint count, limits, speeds, axis order and home "
        "(default: the bundled cell)",
    )
    parser.add_argument(
        "--robot",
        choices=("cell", "plain"),
        default="cell",
        help="the cell's robot (default), or a plain six-axis joint-space model",
    )
    parser.add_argument(
        "--joints",
        help="initial joints in the controller's axis order, degrees or mm, separated by commas (default: the cell's "
        "home)",
    )
    parser.add_argument(
        "--noise-rate", type=float, default=0.0, help="probability of random garbage bytes before a sentence"
    )
    parser.add_argument("--corrupt-rate", type=float, default=0.0, help="probability of a flipped byte in a sentence")
    parser.add_argument("--drop-rate", type=float, default=0.0, help="probability that a sentence is not sent")
    parser.add_argument(
        "--disconnect-after", type=float, metavar="SECONDS", help="vanish after this many seconds (the process ends)"
    )
    parser.add_argument(
        "--reboot-after",
        type=float,
        metavar="SECONDS",
        help="reboot after this many seconds: gone for --reboot-downtime, then back",
    )
    parser.add_argument("--reboot-downtime", type=float, default=1.0, metavar="SECONDS")
    parser.add_argument("--seed", type=int, default=0, help="seed of the fault injection")
    parser.add_argument(
        "--key-file",
        type=Path,
        help="the link key to require on motion sentences (default: the user's, made on first use; see `videocal "
        "link-key`)",
    )
    parser.add_argument(
        "--open",
        action="store_true",
        help="no link key: a protocol-3 controller that obeys any client's MVJ (to test a workstation against an old "
        "controller)",
    )


def run(args: argparse.Namespace) -> int:
    from videocal_sim.controller_sim import ControllerLogic
    from videocal_sim.wire_faults import FaultInjector
    from calib_core.link.joint_motion import PlainJointModel
    from calib_core.link.link_key import read_key, user_key
    from videocal_sim.controller_transport import SimOptions, serve

    if args.link is not None and not args.pty:
        raise VideocalError("--link applies to --pty")
    if args.tcp is not None and not (0 <= args.tcp <= 65535):
        raise VideocalError(f"--tcp: not a port number: {args.tcp}")
    faults = FaultInjector(args.noise_rate, args.corrupt_rate, args.drop_rate, args.seed)
    if args.open and args.key_file is not None:
        raise VideocalError("--open and --key-file exclude each other")
    key = None if args.open else (read_key(args.key_file) if args.key_file is not None else user_key())
    if args.robot == "cell":
        from calib_core.connectors.joint_map import ControllerJointModel, JointMap
        from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

        cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
        robot = cell.load_robot()
        joint_map = JointMap.for_robot(robot.joint_names, cell.robot_spec.controller)
        model = ControllerJointModel.of(robot, joint_map)
        initial = joint_map.to_controller(cell.home_joints_deg)
    else:
        if args.workcell is not None:
            raise VideocalError("--workcell applies to --robot cell")
        model = PlainJointModel()
        initial = np.zeros(6)
    if args.joints:
        try:
            values = np.array([float(v) for v in args.joints.split(",")])
        except ValueError:
            raise VideocalError(
                f"--joints: expected {len(initial)} numbers separated by commas, got {args.joints!r}"
            ) from None
        if values.shape != initial.shape:
            raise VideocalError(f"--joints: the robot has {len(initial)} joints, got {len(values)} values")
        initial = values
    stop = {"flag": False}

    def on_signal(signum, frame):
        stop["flag"] = True

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)

    def announce(path: str) -> None:
        print(path, flush=True)

    options = SimOptions(
        pty=args.pty,
        tcp_port=args.tcp,
        link_path=args.link,
        disconnect_after_s=args.disconnect_after,
        reboot_after_s=args.reboot_after,
        reboot_downtime_s=args.reboot_downtime,
    )
    try:
        logic = ControllerLogic(
            model, initial, key=key, on_refusal=lambda text: print(f"refused: {text}", file=sys.stderr, flush=True)
        )
        serve(logic, options, faults, announce, lambda: stop["flag"])
    except OSError as exc:
        raise VideocalError(f"cannot serve: {exc}") from None
    print(
        f"sent with faults: {faults.noise_bursts} garbage bursts, {faults.corrupted} corrupted, {faults.dropped} "
        "dropped",
        file=sys.stderr,
    )
    return 0
