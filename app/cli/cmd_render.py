"""``videocal render``: write a PNG of the workcell from the modelled camera, the overview
camera, or the simulated true camera.

``--location NAME`` drives the robot (by IK) to the task location's approach pose, from which
the camera sees its component; ``--at-task NAME`` to the task pose itself (where the demo's and the
operator's first look is made: a cell whose approach view looked fine can show too little there);
``--joints`` sets the joints directly; none renders the home pose.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from calib_core.atomic_file import atomic_write_bytes
from calib_core.errors import VideocalError
from calib_core.bundled import DEFAULT_WORKCELL
from app.cli.options import bounded_float

VIEWS = ("virtual", "overview", "true")
OVERVIEW_AZIMUTH_DEG, OVERVIEW_ELEVATION_DEG = -130.0, 32.0
"""The overview's direction, the window's own at start."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--workcell", type=Path, default=DEFAULT_WORKCELL, help="workcell YAML (default: the bundled one)"
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--joints", help="one value per driven joint (deg, or mm for a prismatic joint), comma separated"
    )
    where.add_argument("--location", help="a task location: the robot goes to its approach pose")
    where.add_argument(
        "--at-task",
        metavar="LOCATION",
        help="a task location: the robot goes to the task pose itself, where the first look is made",
    )
    parser.add_argument(
        "--view",
        choices=VIEWS,
        default="virtual",
        help="virtual (modelled camera), overview, or true (the simulated camera on the true robot)",
    )
    parser.add_argument("--out", type=Path, required=True, help="PNG file to write")
    parser.add_argument("--highlight", help="component to highlight (default: the location's component)")
    parser.add_argument("--features", action="store_true", help="show feature points and their names")
    parser.add_argument("--style", choices=("surface", "wireframe", "edges"), default="surface")
    parser.add_argument(
        "--scale",
        type=bounded_float(0.05, 4.0),
        default=1.0,
        help="image size relative to the camera's (virtual and true views)",
    )


def _joints(text: str) -> np.ndarray:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise VideocalError(f"--joints: expected numbers (deg or mm) separated by commas, got {text!r}") from None
    if not np.all(np.isfinite(values)):
        raise VideocalError(f"--joints: expected finite numbers, got {text!r}")
    return np.array(values)


def run(args: argparse.Namespace) -> int:
    if args.out.suffix.lower() != ".png":
        raise VideocalError(f"--out: the image is written as PNG; name it *.png, got {args.out}")
    if not (0.05 <= args.scale <= 4.0):
        raise VideocalError(f"--scale must lie between 0.05 and 4, got {args.scale}")
    from calib_core.render import RenderOptions, SceneRenderer
    from calib_core.robot import solve_ik
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.robot.visuals import RobotVisuals
    from calib_core.workcell import load_workcell

    cell = load_workcell(args.workcell)
    if cell.intrinsics_path is None:
        raise VideocalError(
            f"{cell.path}: field 'camera': the workcell names no camera file (camera.intrinsics): calibrate the camera "
            "first (videocal calibrate-intrinsics)"
        )
    robot = cell.load_robot()
    highlight = args.highlight
    q = np.array(cell.home_joints_deg, dtype=float)
    if args.joints:
        try:
            q = robot.check_joints(_joints(args.joints))
        except ValueError as exc:
            raise VideocalError(f"--joints: {exc}") from None
    elif args.location or args.at_task:
        try:
            task = cell.task(args.location or args.at_task)
        except KeyError as exc:
            raise VideocalError(str(exc.args[0])) from None
        q = solve_ik(robot, task.approach2base, q).q_deg
        if args.at_task:  # from the approach, as the robot gets there
            q = solve_ik(robot, task.tcp2base, q).q_deg
        highlight = highlight or task.component
    if highlight is not None:
        try:
            cell.component(highlight)
        except KeyError as exc:
            raise VideocalError(str(exc.args[0])) from None
    intr = load_intrinsics(cell.intrinsics_path).scaled(args.scale)
    options = RenderOptions(
        highlight=highlight, show_features=args.features, feature_names=args.features, style=args.style
    )
    if args.view == "true":
        from calib_core.plugins import SITES, load_plugin

        image = load_plugin(SITES, "sim").true_view(cell, q, intr)
    else:
        renderer = SceneRenderer()
        items = cell.components + RobotVisuals.from_robot(robot).scene_items(q)
        renderer.set_items(items)
        if args.view == "virtual":
            image = renderer.render_view(intr.without_distortion(), robot.fk(q, "camera"), options)
        else:
            from calib_core.scene_framing import cell_framing, eye_at

            target, distance = cell_framing(items)  # the whole cell, as the window's overview frames it
            image = renderer.render_overview(
                eye_at(target, distance, OVERVIEW_AZIMUTH_DEG, OVERVIEW_ELEVATION_DEG), target, options=options
            )
        renderer.close()
    import cv2

    ok, png = cv2.imencode(".png", np.ascontiguousarray(image[:, :, ::-1]))
    if not ok:
        raise VideocalError("could not encode the image as PNG")
    atomic_write_bytes(args.out, png.tobytes())
    print(
        f"wrote {args.out} ({image.shape[1]} x {image.shape[0]}, {args.view} view, joints "
        f"{', '.join(f'{v:.2f}' for v in q)} deg)"
    )
    return 0
