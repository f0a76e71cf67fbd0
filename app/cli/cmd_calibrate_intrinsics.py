"""``videocal calibrate-intrinsics SOURCE --out FILE``: the camera's intrinsics from calibration board views
(ChArUco, chessboard, circle grid or ArUco grid: ``--board``).

SOURCE is a folder of images, a video file (every ``--every``-th frame), a ROS bag (its image topic, ``--topic``
when it has several), or ``sim`` (views of the
board rendered by the simulated camera, whose truth is then printed beside the result).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from calib_core.errors import VideocalError
from app.cli.options import bounded_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "source", help="a folder of images, a video file, a ROS bag (a bag folder, .mcap or .db3), or 'sim'"
    )
    parser.add_argument("--topic", help="with a bag: the image topic (needed when it has several)")
    parser.add_argument(
        "--board",
        default="charuco:9x7:30:22:DICT_5X5_100",
        help="charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT[:legacy], chessboard:COLSxROWS:SQUARE_MM (inner corners), "
        "circles:COLSxROWS:SPACING_MM[:asymmetric], aruco:COLSxROWS:MARKER_MM:GAP_MM:DICT",
    )
    parser.add_argument(
        "--detector-params", type=Path, help="detector settings YAML (refine_markers, aruco, circle_blobs)"
    )
    parser.add_argument("--out", type=Path, required=True, help="intrinsics file to write (YAML)")
    parser.add_argument("--format", choices=("opencv", "ros"), default="opencv")
    parser.add_argument("--no-distortion", action="store_true", help="fit the pinhole only (as the paper's tool did)")
    parser.add_argument(
        "--k-coefficients",
        type=int,
        choices=(2, 3),
        default=2,
        help="radial distortion terms: 2 (k1 k2, k3 held at 0; the default, as ROS's camera_calibration) or 3 (wide "
        "lenses, with views reaching the image's corners)",
    )
    parser.add_argument(
        "--every",
        type=bounded_int(1, 100_000),
        default=None,
        help="with a video: use every n-th frame (default 15); with a bag: every n-th image (default 1)",
    )
    parser.add_argument("--views", type=bounded_int(3, 500), default=15, help="with 'sim': how many views to render")
    parser.add_argument("--json", action="store_true", help="print the result as JSON")


def run(args: argparse.Namespace) -> int:
    from calib_core.camera.intrinsics_io import save_intrinsics
    from calib_core.vision.board import parse_board
    from calib_core.vision.target_detection import load_detector_settings
    from calib_core.vision.image_sources import folder_images, video_frames
    from app.cli.progress import counted, progress, say
    from calib_core.bags.bag_source import looks_like_bag
    from calib_core.vision.intrinsics_calibration import calibrate_intrinsics, detect_views

    args.every_given = args.every is not None
    args.every = args.every or 15
    if args.topic is not None and args.source == "sim":
        raise VideocalError("--topic applies to a bag source")
    spec = parse_board(args.board)
    settings = load_detector_settings(args.detector_params) if args.detector_params else None
    truth = None
    if args.source == "sim":
        from calib_core.plugins import SITES, load_plugin

        simulated = load_plugin(SITES, "sim")
        print(f"rendering {args.views} simulated views of {spec}...", file=sys.stderr)
        truth, images = simulated.board_images(spec, args.views)
    else:
        from calib_core.bags.bag_source import bag_images, looks_like_bag

        source = Path(args.source)
        if looks_like_bag(source):
            images = bag_images(source, args.topic, args.every if args.every_given else 1)
        elif args.topic is not None:
            raise VideocalError(f"--topic applies to a ROS bag; {source} is not one (a bag folder, .mcap or .db3)")
        elif source.is_dir():
            images = folder_images(source)
        elif source.is_file():
            images = video_frames(source, args.every)
        else:
            raise VideocalError(f"{source}: no such folder or video file (or use 'sim')")
    total = None
    if args.source != "sim" and Path(args.source).is_dir() and not looks_like_bag(Path(args.source)):
        from calib_core.vision.image_sources import IMAGE_SUFFIXES

        total = sum(1 for p in Path(args.source).iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
    with progress(total, "finding the board", args.json) as bar:
        views, rejected = detect_views(counted(images, bar), spec, settings)
        for r in rejected:
            say(bar, f"rejected {r.name}: {r.reason}")
    result = calibrate_intrinsics(
        views, spec, distortion=not args.no_distortion, radial_terms=args.k_coefficients, rejected=rejected
    )
    save_intrinsics(args.out, result.intrinsics, args.format)
    i = result.intrinsics
    summary = {
        "fu": i.fu,
        "fv": i.fv,
        "cx": i.cx,
        "cy": i.cy,
        "distortion": list(i.distortion),
        "rms_px": result.rms_px,
        "std": result.std,
        "coverage": result.coverage,
        "views_used": len(result.used),
        "views_rejected": len(rejected),
        "per_view_rms_px": result.per_view_rms_px,
        "advice": result.advice,
        "out": str(args.out),
    }
    if truth is not None:
        summary["truth"] = {
            "fu": truth.fu,
            "fv": truth.fv,
            "cx": truth.cx,
            "cy": truth.cy,
            "distortion": list(truth.distortion),
        }
    if args.json:
        json.dump(summary, sys.stdout, indent=2)
        sys.stdout.write("\n")
    else:
        print(
            f"{len(result.used)} views used, {len(rejected)} rejected; RMS {result.rms_px:.3f} px; corners cover "
            f"{100 * result.coverage:.0f} % of the image"
        )
        for name in ("fu", "fv", "cx", "cy"):
            t = f"   (truth {getattr(truth, name):.2f})" if truth is not None else ""
            print(f"  {name} = {getattr(i, name):9.2f} +- {result.std[name]:.2f} px{t}")
        print(
            f"  distortion ({i.model}) {' '.join(i.distortion_names)} = " + " ".join(f"{v:+.5f}" for v in i.distortion)
        )
        for line in result.advice:
            print(f"advice: {line}")
        print(f"wrote {args.out}")
    return 0
