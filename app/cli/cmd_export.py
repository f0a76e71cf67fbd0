"""``videocal export WORKSPACE --format F [--out FILE]``: the corrected task locations for a robot
controller (URScript, RAPID, KRL, FANUC TP, PDL2) or a spreadsheet (CSV, JSON); stdout without ``--out``.
``videocal export RECORDING.mcap --format ros2-bag --out FOLDER``: a session recording as a ROS 2 bag."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from app.cli.options import resolved_path
from calib_core.workspace.export_formats import EXPORT_FORMATS

BAG_FORMAT = "ros2-bag"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("workspace", type=Path, help="a workspace file (a recording .mcap with --format ros2-bag)")
    parser.add_argument(
        "--format",
        choices=EXPORT_FORMATS + (BAG_FORMAT,),
        default="csv",
        help="csv, json (every correction, with the target to command), a controller listing: urscript (UR), rapid "
        "(ABB), krl (KUKA), "
        "fanuc (FANUC TP), pdl2 (COMAU), named after --out's file; or ros2-bag (a recording as a ROS 2 bag folder: "
        "images, "
        "joint states in rad and m, camera_info)",
    )
    parser.add_argument("--out", type=Path)
    parser.add_argument(
        "--workcell",
        type=resolved_path,
        help="the cell whose robot gives the tool data of a controller listing, or with ros2-bag each "
        "joint's unit (default: the workspace's or recording's own)",
    )


def run(args: argparse.Namespace) -> int:
    from calib_core.atomic_file import atomic_write_text
    from calib_core.errors import VideocalError

    if args.format == BAG_FORMAT:
        from calib_core.bags.bag_export import recording_to_bag

        if args.out is None:
            raise VideocalError("--format ros2-bag writes a bag folder: give --out FOLDER")
        counts = recording_to_bag(args.workspace, args.out, **_bag_cell(args))
        print(f"wrote {args.out}: " + ", ".join(f"{n} on {topic}" for topic, n in counts.items()))
        return 0
    from calib_core.workspace.exports import export_corrections
    from calib_core.workspace.workspace import load_workspace

    from calib_core.workspace.controller_formats import left_out

    ws = load_workspace(args.workspace)
    if args.format not in ("json", "csv") and not ws.corrections.corrected_tasks():
        raise VideocalError(
            f"{args.workspace}: no task location holds a correction, nothing to command"
            + "".join(f"; {line}" for line in left_out(ws.corrections))
        )
    robot, joint_map = _robot(args.workcell or ws.workcell_path)
    text = export_corrections(
        args.format,
        ws.corrections,
        ws.task_locations,
        args.out.name.split(".")[0] if args.out else None,
        robot,
        joint_map,
    )
    if args.format not in ("json", "csv"):
        for line in left_out(ws.corrections):
            print(line, file=sys.stderr)
    if args.out:
        atomic_write_text(args.out, text)
        print(f"wrote {args.out}")
    else:
        sys.stdout.write(text)
    return 0


def _bag_cell(args) -> dict:
    """What the cell gives a bag: each joint's unit and the camera's mounting on /tf_static, from ``--workcell`` or the
    recording's own workcell when it is still there (without either the units are asked for and no mounting is
    written)."""
    from calib_core.bags.bag_export import cell_mounting
    from calib_core.recording.reader import read_recording
    from calib_core.recording.schemas import SETUP_TOPIC
    from calib_core.workcell import load_workcell

    path = args.workcell
    if path is None:
        setups = read_recording(args.workspace).topic(SETUP_TOPIC)
        named = setups[-1].payload.get("workcell") if setups else None
        path = Path(named) if named and Path(named).is_file() else None
    if path is None:
        return {}
    workcell = load_workcell(path)
    return {"joint_units": list(workcell.load_robot().joint_units), "mounting": cell_mounting(workcell)}


def _robot(workcell: str | Path | None):
    """The workcell's robot and its joint map (model joints to controller axes), for the tool data and the arm's
    configurations of a listing; ``(None, None)`` (the listing then has neither, and says so) when the workspace names
    no workcell or it is not there."""
    if not workcell or not Path(workcell).is_file():
        print(
            f"note: no tool data or arm configurations in the export: the workcell {workcell or '(not named)'} is not "
            "there (give --workcell)",
            file=sys.stderr,
        )
        return None, None
    from calib_core.connectors.joint_map import JointMap
    from calib_core.workcell import load_workcell

    cell = load_workcell(workcell)
    robot = cell.load_robot()
    return robot, JointMap.for_robot(robot.joint_names, cell.robot_spec.controller)
