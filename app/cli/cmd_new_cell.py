"""``videocal new-cell DIR --urdf FILE``: a starting cell for a robot description (URDF or xacro)
that loads and renders at once: the robot with its frames named, a floor, an example target with
named features, a camera file and a task location in reach."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("folder", type=Path, help="the folder to write (created; must not hold a workcell.yaml)")
    parser.add_argument("--urdf", type=Path, required=True, help="the robot description: a URDF or a xacro file")
    parser.add_argument(
        "--package-path",
        type=Path,
        action="append",
        default=[],
        metavar="P",
        help="a folder that holds the packages $(find) and package:// name, or a checkout holding them (repeat for "
        "more; ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are searched too)",
    )
    parser.add_argument(
        "--xacro-arg",
        action="append",
        default=[],
        metavar="NAME:=VALUE",
        help="a xacro argument, as ROS writes it (ur_type:=ur10e; repeat for more); kept in the cell",
    )
    parser.add_argument(
        "--flange",
        help="the URDF frame the tool is mounted on, z out of the tool (default: tool0, flange, or the last link)",
    )
    parser.add_argument("--name", help="the cell's name (default: from the URDF)")


def run(args: argparse.Namespace) -> int:
    from calib_core.workcell.starter import write_starter_cell

    from calib_core.errors import VideocalError

    xacro_args = {}
    for item in args.xacro_arg:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise VideocalError(f"--xacro-arg {item!r}: write it as NAME:=VALUE (ur_type:=ur10e)")
        xacro_args[name.strip()] = value
    made = write_starter_cell(
        args.folder, args.urdf, args.package_path, flange=args.flange, name=args.name, xacro_args=xacro_args
    )
    print(f"wrote {made.workcell_path}")
    print(
        f"  flange {made.flange} ({made.flange_why}), base {made.base or '(URDF root)'}, held joints: "
        f"{', '.join(made.held_joints) or 'none'}"
    )
    if made.tool_axis_warning:
        print(f"  warning: {made.tool_axis_warning}")
    print(f"  home joints: {', '.join(f'{v:.1f}' for v in made.home_joints)}")
    print(
        f"next: videocal render --workcell {made.workcell_path} --location target_grasp --view overview --out "
        "overview.png"
    )
    return 0
