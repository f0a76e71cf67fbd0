"""``videocal sim-ros2``: the simulated ros2_control arm of a cell on Cyclone DDS (``videocal_sim.ros2_arm``).
Prints ``ready`` once it publishes; runs until SIGTERM or Ctrl-C."""

from __future__ import annotations

import argparse
import signal
import threading

from app.cli.options import bounded_float, resolved_path

HELP = (
    "serve a cell's robot as a simulated ros2_control arm (joint_states, a joint trajectory controller) on Cyclone DDS"
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--workcell", type=resolved_path, default=None, help="the cell whose robot it is (default: the bundled one)"
    )
    parser.add_argument(
        "--rate", type=bounded_float(1.0, 2000.0), default=100.0, help="joint_states rate, Hz (default 100)"
    )
    parser.add_argument("--controller", default="joint_trajectory_controller", help="the trajectory controller's name")
    parser.add_argument("--joint-states", default="/joint_states", help="the joint states topic")
    parser.add_argument("--domain", type=int, default=None, help="ROS domain id (default: ROS_DOMAIN_ID, else 0)")
    parser.add_argument(
        "--joints", help="initial joints in URDF order, deg or mm, separated by commas (default: the cell's home)"
    )


def run(args: argparse.Namespace) -> int:
    from calib_core.operator.cell import Cell
    from calib_core.ros2.joint_units import user_per_si
    from calib_core.ros2.wire import domain_id
    from calib_core.workcell import DEFAULT_WORKCELL
    from videocal_sim.ros2_arm import SimulatedRos2Arm
    from videocal_sim.sim_process import joints_option

    cell = Cell.open(args.workcell or DEFAULT_WORKCELL)
    robot = cell.robot
    initial = joints_option(args.joints, robot.n_joints, cell.home_joints)
    arm = SimulatedRos2Arm(
        robot.joint_names,
        user_per_si(robot.joint_units),
        robot.lower_limits_deg,
        robot.upper_limits_deg,
        initial,
        rate_hz=args.rate,
        domain=domain_id(args.domain),
        controller=args.controller,
        joint_states=args.joint_states,
    ).start()
    done = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: done.set())
    print("ready", flush=True)
    done.wait()
    arm.close()
    return 0
