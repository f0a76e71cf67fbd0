"""``videocal calibrate-robot sim|FILE --out DIR``: the robot's geometric parameters and its camera
mounting from views of a board at many poses (docs/calibration.md).

``sim`` runs it on the simulator's cold cell (videocal_sim/cold_cell.py): the poses planned, the robot
driven through them, each view rendered by the true camera and detected, the camera's intrinsics
calibrated from the same views first, surveyed features located at each task location, the gripper
closed on each task's fixture for the tool; the result scored against the truth, which nothing else
reads. ``FILE`` is a CSV of images and joints (``image[,component],<joint names | j1..jn>``,
docs/calibration.md) of the cell's robot (``--workcell``) viewing a board, or with ``component`` one of
the cell's surveyed components (their edges tie the robot's base to the cell); ``--grasps`` a CSV of
``task[,image],<joints>``: the gripper closed on each task's pin, seen when its frame is given. A ROS 2
bag gives board views with the joints from its JointState at each image's stamp, where the arm stood still.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from app.cli.bag_options import add_bag_arguments
from app.cli.options import bounded_int
from calib_core.errors import VideocalError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "source",
        help="'sim' (the cold cell of the simulated test bed), a CSV of image[,component],<joints> views, a folder "
        "holding views.csv (and grasps.csv), "
        "or a ROS 2 bag (a bag folder, .mcap or .db3: board images, /joint_states, CameraInfo)",
    )
    add_bag_arguments(parser)
    parser.add_argument(
        "--views", type=bounded_int(8, 200), default=40, help="with 'sim': poses to view the board from (8 to 200)"
    )
    parser.add_argument(
        "--fixed-intrinsics",
        action="store_true",
        help="keep the camera's intrinsics as calibrated from the same views (or given by --intrinsics) instead of "
        "refining them with the robot",
    )
    parser.add_argument(
        "--seed",
        type=bounded_int(0, 10_000),
        default=0,
        help="with 'sim': which cold cell (its errors are drawn from this)",
    )
    parser.add_argument(
        "--workcell", type=Path, help="with a CSV: the cell whose robot took the views (default: the bundled one)"
    )
    parser.add_argument("--board", help="with a CSV: the board (default charuco:9x7:30:22:DICT_5X5_100)")
    parser.add_argument(
        "--intrinsics",
        type=Path,
        help="with a CSV or a bag: the camera's intrinsics file (default: a bag's CameraInfo, else calibrated from the "
        "same views)",
    )
    parser.add_argument(
        "--grasps",
        type=Path,
        help="with a CSV: a CSV of task[,image],<joints> reported with the gripper closed in compliance on each task "
        "location's fixture pin: the TCP measured from the camera (default: the folder's grasps.csv)",
    )
    parser.add_argument(
        "--detector-params", type=Path, help="detector settings YAML (refine_markers, aruco, circle_blobs)"
    )
    parser.add_argument(
        "--out", type=Path, required=True, help="folder for robot_calibration.yaml and the calibrated URDF"
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    from app.cli.progress import progress

    with progress(None, "views", args.json) as bar:
        return _run(args, bar)


def _run(args: argparse.Namespace, bar) -> int:
    from app.cli.progress import reported, say
    from calib_core.robot_calibration.report import save_robot_calibration

    if args.source == "sim":
        from calib_core.plugins import SITES, load_plugin

        run_ = load_plugin(SITES, "sim").calibrate_robot(
            args.views,
            args.seed,
            with_intrinsics=not args.fixed_intrinsics,
            progress=reported(bar),
            say=lambda text: say(bar, text),
        )
        result, robot, nominal, tool, rejected, score = (
            run_.result,
            run_.robot,
            run_.nominal_robot,
            run_.tool,
            run_.rejected,
            run_.score,
        )
        intrinsics_rms = run_.intrinsics.rms_px
        counts = {"board_views": run_.board_views, "cell_views": run_.cell_views}
    else:
        grasps = None
        folder = Path(args.source)
        if args.grasps is None and folder.is_dir() and (folder / "grasps.csv").is_file():
            args.grasps = folder / "grasps.csv"
            print(f"grasps from {args.grasps}", file=sys.stderr)
        if args.grasps is not None:  # read first: a mistake in it is found before the identification's work
            from calib_core.robot_calibration.grasp_file import load_grasps
            from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

            cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
            grasps = load_grasps(args.grasps, cell.load_robot().joint_names, cell)
        result, nominal, rejected, intrinsics_rms, counts = _from_files(args, bar)
        robot, tool, score = result.robot, None, None
        if grasps is not None:
            from calib_core.robot_calibration.camera_to_tool import camera_to_tool, with_tool

            tool = camera_to_tool(result.robot, _seen_grasps(grasps, args.grasps, result, cell))
            robot = with_tool(result.robot, tool.tcp2cam)
    for r in rejected:
        print(f"rejected {r}", file=sys.stderr)
    args.out.mkdir(parents=True, exist_ok=True)
    save_robot_calibration(args.out, result, nominal, robot=robot, tool=tool)
    summary = {
        "views": len(result.per_view_rms_px),
        **counts,
        "rejected": rejected,
        "rms_px": result.rms_px,
        "start_rms_px": result.start_rms_px,
        "seconds": result.seconds,
        "identified": len(result.observability.identified),
        "of": len(result.names),
        "condition": result.observability.condition,
        "intrinsics_rms_px": intrinsics_rms,
        "warnings": list(result.warnings),
        "out": str(args.out),
    }
    if tool is not None:
        summary["tool"] = {
            "grasps": len(tool.per_grasp),
            "seen": tool.seen_grasps,
            "spread_mm": tool.spread_mm,
            "spread_deg": tool.spread_deg,
        }
    if score is not None:
        summary["score"] = score
    if args.json:
        json.dump(summary, sys.stdout, indent=2, default=float)
        sys.stdout.write("\n")
        return 0
    print(
        f"{counts['board_views']} board views, {counts['cell_views']} views of surveyed components; RMS "
        f"{result.start_rms_px:.2f} px with the nominal model -> {result.rms_px:.3f} px; {summary['identified']} of "
        f"{summary['of']} parameters identified (condition {result.observability.condition:.0f}) in "
        f"{result.seconds:.1f} s"
    )
    for w in result.warnings:
        print(f"warning: {w}")
    for key, value in (score or {}).items():
        print(f"  {key}: {value}")
    print(f"wrote {args.out}")
    return 0


def _from_files(args, bar):
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.robot_calibration.identify_robot import CellFrame, identify_robot
    from calib_core.robot_calibration.observations import PoseView
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.hand_eye_data import load_posed_images
    from calib_core.vision.intrinsics_calibration import BoardView, calibrate_intrinsics, detect_view
    from calib_core.vision.target_detection import load_detector_settings
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    from calib_core.bags.bag_source import looks_like_bag

    source = Path(args.source)
    if not source.exists():
        raise VideocalError(f"{source}: no such file (or use 'sim')")
    if looks_like_bag(source):
        return _from_bag(args, source)
    if args.topic is not None or args.joint_topic is not None:
        raise VideocalError(
            f"--topic and --joint-topic apply to a ROS bag; {source} is not one (a bag folder, .mcap or .db3)"
        )
    data = load_posed_images(source)
    if data.joint_columns is None:
        raise VideocalError(
            f"{data.source}: a robot calibration needs the joints of every view (a CSV of image,<joint names or "
            "j1..jn>), not flange poses"
        )
    cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
    robot = cell.load_robot()
    order = data.joint_order(robot.joint_names)
    components = {c.name for c in cell.components if c.features}
    for posed in data.views:  # before any work: a view of a component the cell does not survey
        if posed.component is not None and posed.component not in components:
            raise VideocalError(
                f"{data.source}: view {posed.name}: no surveyed component {posed.component!r} in {cell.path.name} "
                "(components with features: "
                f"{', '.join(sorted(components)) or 'none'})"
            )
    spec = parse_board(args.board or data.board_text or DEFAULT_SPEC)
    if not spec.unambiguous:
        from calib_core.vision.target_spec import turn_ambiguity

        raise VideocalError(turn_ambiguity(spec, "a robot calibration"))
    detect = spec.detector(load_detector_settings(args.detector_params) if args.detector_params else None)
    corners = spec.corners_mm()
    board_views, views, rejected, size, of_components = [], [], [], None, []
    bar.reset(total=len(data.views))
    for posed in data.views:
        image, size = data.read_image_sized(posed, size)
        if posed.component is not None:
            of_components.append(posed)  # located once the intrinsics are known
            continue
        v = detect_view(posed.name, image, spec, detect)
        if isinstance(v, BoardView):
            board_views.append(v)
            views.append(PoseView(posed.name, posed.joints_deg[order], corners[v.ids], v.corners_px))
        else:
            rejected.append(f"{posed.name}: {v.reason}")
        bar.update()
    if args.intrinsics is not None:
        intrinsics, rms = load_intrinsics(args.intrinsics, image_size=size), None
    else:
        calibrated = calibrate_intrinsics(board_views, spec, rejected=[])
        intrinsics, rms = calibrated.intrinsics, calibrated.rms_px
    frames = [
        CellFrame(posed.component, posed.joints_deg[order], data.read_image(posed), posed.name)
        for posed in of_components
    ]
    done = identify_robot(robot, intrinsics, cell, views, frames, with_intrinsics=not args.fixed_intrinsics)
    return done.result, robot, rejected, rms, {"board_views": done.board_views, "cell_views": done.cell_views}


def _from_bag(args, source: Path):
    """Board views from a ROS 2 bag: its images (``--topic``) where the arm stood still, the joints from its
    JointState at each image's stamp; the intrinsics from ``--intrinsics``, the bag's CameraInfo, or the views."""
    from calib_core.bags.bag_source import bag_intrinsics
    from calib_core.bags.board_views import bag_board_views, joints_settled
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.robot_calibration.identify_robot import identify_robot
    from calib_core.robot_calibration.observations import PoseView
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.intrinsics_calibration import calibrate_intrinsics
    from calib_core.vision.target_detection import load_detector_settings
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
    robot = cell.load_robot()
    spec = parse_board(args.board or DEFAULT_SPEC)
    if not spec.unambiguous:
        from calib_core.vision.target_spec import turn_ambiguity

        raise VideocalError(turn_ambiguity(spec, "a robot calibration"))
    detect = spec.detector(load_detector_settings(args.detector_params) if args.detector_params else None)
    found = bag_board_views(
        source, spec, detect, joints_settled(source, robot, args.joint_topic), topic=args.topic, every=args.every
    )
    for why in found.skipped:  # the rejected ones are said with the identification's (run)
        print(f"skipped {why}", file=sys.stderr)
    print(f"{source}: {found.summary}", file=sys.stderr)
    if not found.views:
        raise VideocalError(f"{source}: no still view of the board ({found.summary})")
    corners = spec.corners_mm()
    views = [PoseView(v.name, q, corners[v.ids], v.corners_px) for v, q in found.views]
    rms = None
    if args.intrinsics is not None:
        intrinsics = load_intrinsics(args.intrinsics, image_size=found.size)
    else:
        intrinsics = bag_intrinsics(source, found.size)
        if intrinsics is None:
            calibrated = calibrate_intrinsics([v for v, _ in found.views], spec, rejected=[])
            intrinsics, rms = calibrated.intrinsics, calibrated.rms_px
            print(
                f"{source}: no CameraInfo: the intrinsics calibrated from the same views (RMS {rms:.2f} px)",
                file=sys.stderr,
            )
    done = identify_robot(robot, intrinsics, cell, views, [], with_intrinsics=not args.fixed_intrinsics)
    return done.result, robot, found.rejected, rms, {"board_views": done.board_views, "cell_views": done.cell_views}


def _seen_grasps(rows, grasps_path: Path, result, cell) -> list:
    """The grasps of the file ``grasps_path``, each seen on its frame when one is given (the held
    fixture's edges give the tool); one not seen is kept through the robot and the survey, and said so."""
    from calib_core.documents import read_grey_image
    from calib_core.robot_calibration.camera_to_tool import Grasp
    from calib_core.robot_calibration.grasp_view import GraspNotSeenError, see_grasp

    grasps = []
    for row in rows:
        g = row.grasp
        if row.image_path is None:
            grasps.append(g)
            continue
        image = read_grey_image(row.image_path, grasps_path, g.name)
        try:
            grasps.append(
                Grasp(
                    g.name,
                    g.joints_deg,
                    g.tcp2base,
                    see_grasp(image, result.intrinsics, result.robot, cell, cell.task(row.task), g.joints_deg),
                )
            )
        except GraspNotSeenError as e:
            print(f"grasp {g.name}: {e}: taken through the robot and the survey", file=sys.stderr)
            grasps.append(g)
    return grasps
