"""``videocal calibrate-hand-eye SOURCE --out FILE``: the camera's mounting from robot poses and board views.

SOURCE is ``sim`` (the simulated test bed, its truth printed beside the result), a ROS-Industrial
``cal_data.yaml`` (or its folder), a CSV of images with flange poses or joints, or a ROS 2 bag (the flange pose at
each image's stamp from ``/joint_states`` through the cell's robot, only where the arm stood still; the
intrinsics from its CameraInfo unless ``--intrinsics``) (docs/calibration.md). A camera on the robot gives
``cam2flange``; a static camera
(``--static-camera``, or the data file's ``static_camera``) gives ``cam2base``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


from calib_core.errors import VideocalError
from app.cli.bag_options import add_bag_arguments
from app.cli.options import bounded_float, bounded_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "source",
        help="'sim', a cal_data.yaml (or its folder), a CSV of image,x_mm,y_mm,z_mm,qx,qy,qz,qw or image,<joints>, "
        "a JSON list of {image, flange2base} (4 x 4, metres), "
        "or a ROS 2 bag (a bag folder, .mcap or .db3: images, /joint_states, CameraInfo)",
    )
    add_bag_arguments(parser)
    parser.add_argument(
        "--flange-from",
        choices=("auto", "joints", "tf"),
        default="auto",
        help="with a bag: the flange pose from the joint states through the cell's robot, or from /tf (default: the "
        "joints when the bag has a JointState topic, else /tf)",
    )
    parser.add_argument(
        "--base-frame", help="with a bag's /tf: the robot's base frame (default: the workcell's base link)"
    )
    parser.add_argument(
        "--flange-frame", help="with a bag's /tf: the flange frame (default: the workcell's flange link)"
    )
    parser.add_argument(
        "--workcell",
        type=Path,
        help="the cell whose robot turns joints into flange poses (a CSV of joints), or whose robot and camera are "
        "simulated (sim)",
    )
    parser.add_argument(
        "--board", help="the board (default: the data file's target_finder, else charuco:9x7:30:22:DICT_5X5_100)"
    )
    parser.add_argument(
        "--intrinsics",
        type=Path,
        help="the camera's intrinsics file (OpenCV or ROS YAML; without an image size the images' size is taken); "
        "default: the data file's intrinsics",
    )
    parser.add_argument(
        "--detector-params", type=Path, help="detector settings YAML (refine_markers, aruco, circle_blobs)"
    )
    mount = parser.add_mutually_exclusive_group()
    mount.add_argument(
        "--static-camera",
        dest="static",
        action="store_const",
        const=True,
        help="the camera stands in the cell and the robot holds the board",
    )
    mount.add_argument(
        "--camera-on-robot",
        dest="static",
        action="store_const",
        const=False,
        help="the camera is on the robot's flange (the default)",
    )
    parser.add_argument(
        "--pose-sigma-mm",
        type=bounded_float(0.001, 100.0),
        default=1.0,
        help="how well the robot's poses are known, 1-sigma mm (sets when views are said to disagree)",
    )
    parser.add_argument(
        "--poses",
        type=bounded_int(3, 200),
        default=10,
        help="with 'sim': robot poses to view the board from (3 to 200)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        required=True,
        action="append",
        help="where to write the mounting, in the form the name asks (repeat for several): .yaml videocal's (xyz mm, "
        "rpy deg, "
        "1-sigma); .launch.py a ROS 2 launch file running tf2_ros's static_transform_publisher; .urdf or .xacro a "
        "fixed-joint snippet for the robot's description",
    )
    parser.add_argument(
        "--parent-frame",
        help="the ROS frame the camera hangs from in the .launch.py and .urdf outputs (default: the workcell's "
        "site.camera_parent_frame, else its robot's flange link, else tool0; the base link for --static-camera)",
    )
    parser.add_argument(
        "--camera-frame",
        help="the camera's ROS frame in those outputs: the camera driver's optical frame (default: the workcell's "
        "site.camera_frame, else videocal_camera_optical_frame)",
    )
    parser.add_argument(
        "--robot-errors",
        action="store_true",
        help="with 'sim': give the simulated robot its joint, link and base errors too (shows why hand-eye calibration "
        "needs accurate kinematics)",
    )
    parser.add_argument("--json", action="store_true", help="print the result as JSON")


def run(args: argparse.Namespace) -> int:
    from calib_core.vision.hand_eye_io import hand_eye_document

    if args.source == "sim":
        result, truth = _simulated(args)
    else:
        result, truth = _from_files(args), None
    written = _write_outputs(args, result)
    doc = hand_eye_document(result)
    if truth is not None:
        doc["error_against_truth"] = truth
    if args.json:
        json.dump(doc, sys.stdout, indent=2)
        sys.stdout.write("\n")
        return 0
    camera = "cam2base" if result.static_camera else "cam2flange"
    print(f"{result.views} poses, RMS {result.rms_px:.3f} px (the corners' own noise {result.noise_px:.3f} px)")
    print(
        f"{camera} xyz {', '.join(f'{v:.3f}' for v in result.camera2mount[:3, 3])} mm (1-sigma "
        f"{', '.join(f'{v:.3f}' for v in result.std_xyz_mm)})"
    )
    if truth is not None:
        print(f"error against the test bed's truth: {truth['mm']:.3f} mm, {truth['deg']:.4f} deg")
    for w in result.warnings:
        print(f"warning: {w}")
    for path in written:
        print(f"wrote {path}")
    return 0


def _write_outputs(args, result) -> list[Path]:
    """Each ``--out`` in the form its name asks; the ROS forms name ``--parent-frame`` (or the cell's flange)."""
    from calib_core.atomic_file import atomic_write_text
    from calib_core.ros2.mounting_out import mounting_text_for
    from calib_core.vision.hand_eye_io import save_hand_eye

    from calib_core.ros2.frame_names import camera_frames

    workcell = None
    if args.workcell is not None:
        from calib_core.workcell import load_workcell

        workcell = load_workcell(args.workcell)
    parent, child = camera_frames(workcell, static_camera=result.static_camera)
    parent, child = args.parent_frame or parent, args.camera_frame or child
    note = (
        f"{result.views} poses, RMS {result.rms_px:.3f} px, 1-sigma "
        f"{', '.join(f'{v:.3f}' for v in result.std_xyz_mm)} mm"
    )
    for path in args.out:
        text = mounting_text_for(path, result.camera2mount, parent, child=child, note=note)
        if text is None:
            save_hand_eye(path, result)
        else:
            atomic_write_text(path, text)
    return list(args.out)


def _detector(args, spec):
    from calib_core.vision.target_detection import load_detector_settings

    return spec.detector(load_detector_settings(args.detector_params) if args.detector_params else None)


def _from_bag(args, source: Path):
    """Hand-eye from a ROS 2 bag: the board's images on ``--topic`` (the only image topic by default), the flange pose
    at
    each image's stamp from ``/joint_states`` through the cell's robot or from ``/tf``, taken only where the arm stood
    still; the camera's intrinsics from ``--intrinsics`` or the bag's CameraInfo."""
    from calib_core.bags.bag_source import bag_intrinsics, bag_topics
    from calib_core.bags.board_views import bag_board_views, flange_settled, joints_settled
    from calib_core.bags.joint_track import JOINT_STATE
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.hand_eye import calibrate_hand_eye
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    cell = load_workcell(args.workcell or DEFAULT_WORKCELL)
    robot = cell.load_robot()
    spec = parse_board(args.board or DEFAULT_SPEC)
    use_tf = args.flange_from == "tf" or (
        args.flange_from == "auto"
        and args.joint_topic is None
        and not any(t.msgtype == JOINT_STATE and t.count for t in bag_topics(source))
    )
    if use_tf:
        frames = cell.robot_spec.frames
        base, flange = (
            args.base_frame or str(frames.get("base") or "base_link"),
            args.flange_frame or str(frames.get("flange") or "tool0"),
        )
        settled, to_flange = flange_settled(source, base, flange), lambda pose: pose
        print(f"{source}: the flange ({flange} in {base}) from /tf", file=sys.stderr)
    else:
        settled, to_flange = joints_settled(source, robot, args.joint_topic), lambda q: robot.fk(q, "flange")
    found = bag_board_views(
        source,
        spec,
        _detector(args, spec),
        settled,
        topic=args.topic,
        every=args.every,
        say=lambda text: print(text, file=sys.stderr),
    )
    print(f"{source}: {found.summary}", file=sys.stderr)
    views = [v for v, _ in found.views]
    flanges = [to_flange(pose) for _, pose in found.views]
    size = found.size
    intrinsics = (
        load_intrinsics(args.intrinsics, image_size=size)
        if args.intrinsics is not None
        else bag_intrinsics(source, size)
    )
    if intrinsics is None:
        raise VideocalError(f"{source}: the bag has no CameraInfo: pass --intrinsics FILE")
    static = bool(args.static)
    return calibrate_hand_eye(views, flanges, spec, intrinsics, static_camera=static, pose_sigma_mm=args.pose_sigma_mm)


def _from_files(args):
    from calib_core.camera.intrinsics import Intrinsics
    from calib_core.camera.intrinsics_io import load_intrinsics
    from calib_core.vision.board import DEFAULT_SPEC, parse_board
    from calib_core.vision.hand_eye import calibrate_hand_eye
    from calib_core.vision.hand_eye_data import load_posed_images
    from app.cli.progress import counted, progress

    source = Path(args.source)
    if not source.exists():
        raise VideocalError(f"{source}: no such file or folder (or use 'sim')")
    from calib_core.bags.bag_source import looks_like_bag

    if looks_like_bag(source) and not source.name.endswith(".yaml"):
        return _from_bag(args, source)
    bag_only = [
        flag
        for flag, given in (
            ("--topic", args.topic),
            ("--joint-topic", args.joint_topic),
            ("--flange-from", args.flange_from != "auto"),
            ("--base-frame", args.base_frame),
            ("--flange-frame", args.flange_frame),
        )
        if given
    ]
    if bag_only:
        raise VideocalError(
            f"{', '.join(bag_only)} appl{'ies' if len(bag_only) == 1 else 'y'} to a ROS bag; {source} is not one (a "
            "bag folder, .mcap or .db3)"
        )
    data = load_posed_images(source)
    spec = parse_board(args.board or data.board_text or DEFAULT_SPEC)
    static = args.static if args.static is not None else bool(data.static_camera)
    robot = None
    if data.joint_columns is not None:
        from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

        robot = load_workcell(args.workcell or DEFAULT_WORKCELL).load_robot()
        order = data.joint_order(robot.joint_names)
    detect = _detector(args, spec)
    views, flanges, size = [], [], None
    with progress(len(data.views), "finding the board", args.json) as bar:
        for posed in counted(data.views, bar):
            found = _board_view(posed, data, spec, detect, size, bar)
            if found is None:
                continue
            v, size = found
            views.append(v)
            flanges.append(
                posed.flange2base if posed.flange2base is not None else robot.fk(posed.joints_deg[order], "flange")
            )
    if args.intrinsics is not None:
        intrinsics = load_intrinsics(args.intrinsics, image_size=size)
    elif data.pinhole is not None:
        intrinsics = Intrinsics(*data.pinhole, size[0], size[1], (0.0,) * 5)
    else:
        raise VideocalError(f"{data.source}: the data file gives no intrinsics: pass --intrinsics FILE")
    return calibrate_hand_eye(views, flanges, spec, intrinsics, static_camera=static, pose_sigma_mm=args.pose_sigma_mm)


def _simulated(args):
    from calib_core.plugins import SITES, load_plugin

    if args.intrinsics is not None:
        raise VideocalError(
            "--intrinsics is not used with 'sim': the simulated camera's intrinsics are the bundled cell's"
        )
    simulated = load_plugin(SITES, "sim")
    return simulated.hand_eye(
        board=args.board,
        workcell=args.workcell,
        robot_errors=args.robot_errors,
        poses=args.poses,
        detector_params=args.detector_params,
        pose_sigma_mm=args.pose_sigma_mm,
    )


def _board_view(posed, data, spec, detect, size, bar):
    """``(view, image size)`` of one posed image whose board was found; ``None`` (said) when it shows a component
    instead, or no board. A size other than the first image's (``size``) is refused: one calibration is for one
    camera mode."""
    from app.cli.progress import say
    from calib_core.vision.intrinsics_calibration import BoardView, detect_view

    if posed.component is not None:
        say(
            bar,
            f"skipped {posed.name}: a view of {posed.component}, not of the board (hand-eye uses board views; "
            "calibrate-robot uses both)",
        )
        return None
    image, size = data.read_image_sized(posed, size)
    v = detect_view(posed.name, image, spec, detect)
    if not isinstance(v, BoardView):
        say(bar, f"rejected {posed.name}: {v.reason}")
        return None
    return v, size
