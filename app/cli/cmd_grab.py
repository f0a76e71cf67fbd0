"""``videocal grab SPEC --count N --out DIR``: N frames from any camera connector as PNG files and ``frames.csv``
(``file``, ``t_device_ns`` where the camera stamps its frames, ``t_host_s``: the host's monotonic clock at the
exposure). A camera that goes quiet is waited for up to ``--wait`` seconds, and said; the frames already grabbed
are kept whatever happens. Exit 0 with N frames, 4 when the camera stayed silent too long, 2 for a bad spec."""

from __future__ import annotations

import argparse
import sys
import time

from app.cli.options import bounded_float, bounded_int, resolved_path

EXIT_SILENT = 4


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "spec",
        help="a camera spec: an OpenCV device number, a video file, a folder, rtsp://, ros2:///camera/image_raw, ...",
    )
    parser.add_argument("--count", type=bounded_int(1, 1_000_000), required=True, help="how many frames")
    parser.add_argument(
        "--out",
        type=resolved_path,
        required=True,
        help="the folder for the PNG files and frames.csv (made if missing; must hold no frames.csv)",
    )
    parser.add_argument(
        "--wait",
        type=bounded_float(0.1, 3600.0),
        default=10.0,
        help="how long a silent camera is waited for, s (default 10)",
    )


def run(args: argparse.Namespace) -> int:
    import cv2

    from calib_core.atomic_file import atomic_write_bytes, atomic_write_text
    from calib_core.connectors.registry import open_camera
    from calib_core.errors import VideocalError
    from calib_core.connectors.frame import FrameTimeout

    if args.out.exists() and not args.out.is_dir():
        raise VideocalError(f"{args.out}: --out names a file; grab writes PNG files and frames.csv into a folder")
    blocking = next((parent for parent in args.out.parents if parent.exists() and not parent.is_dir()), None)
    if blocking is not None:
        raise VideocalError(f"{args.out}: cannot make the folder: {blocking} is a file")
    if (args.out / "frames.csv").exists():
        raise VideocalError(f"{args.out / 'frames.csv'} exists: grab into an empty folder (nothing was overwritten)")
    camera = open_camera(args.spec)  # before anything is made: a camera that does not open leaves nothing behind
    made = [d for d in (args.out, *args.out.parents) if not d.exists()]
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        camera.close()
        raise VideocalError(f"{args.out}: cannot make the folder ({exc.strerror or exc})") from None
    rows = ["file,t_device_ns,t_host_s"]
    code = 0
    silent_since = None
    try:
        while len(rows) - 1 < args.count:
            try:
                frame = camera.read()
            except FrameTimeout as exc:
                now = time.monotonic()
                if silent_since is None:
                    silent_since = now
                    print(f"waiting: {exc}", file=sys.stderr, flush=True)
                if now - silent_since > args.wait:
                    print(
                        f"error: {args.spec}: no frame for {now - silent_since:.1f} s (--wait {args.wait:g}); "
                        f"{_kept(rows, args)}",
                        file=sys.stderr,
                    )
                    code = EXIT_SILENT
                    break
                continue
            if frame is None:
                print(
                    f"error: {args.spec}: the stream ended after {len(rows) - 1} of {args.count} frames "
                    f"({_kept(rows, args)})",
                    file=sys.stderr,
                )
                code = EXIT_SILENT
                break
            if silent_since is not None:
                print(f"the camera is back after {time.monotonic() - silent_since:.1f} s", file=sys.stderr, flush=True)
                silent_since = None
            name = f"frame_{len(rows) - 1:06d}.png"
            ok, png = cv2.imencode(".png", cv2.cvtColor(frame.image, cv2.COLOR_RGB2BGR))
            if not ok:
                raise VideocalError(f"{args.spec}: frame {frame.index} could not be encoded as PNG")
            atomic_write_bytes(args.out / name, png.tobytes())
            rows.append(f"{name},{'' if frame.t_device_ns is None else frame.t_device_ns},{frame.t_host_s:.6f}")
    finally:
        camera.close()
        if len(rows) > 1:
            atomic_write_text(args.out / "frames.csv", "\n".join(rows) + "\n")
        else:  # not one frame: nothing is left behind, not even the folders grab made
            for folder in made:
                try:
                    folder.rmdir()
                except OSError:
                    break
    if code == 0:
        print(f"{args.count} frames and frames.csv in {args.out}")
    return code


def _kept(rows: list[str], args) -> str:
    """What a grab that ended early leaves: the frames it got, or nothing at all."""
    got = len(rows) - 1
    return (
        f"{got} of {args.count} frames kept in {args.out}"
        if got
        else f"0 of {args.count} frames: nothing was left behind"
    )
