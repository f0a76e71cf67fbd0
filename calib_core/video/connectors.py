"""The built-in camera connectors: OpenCV devices, video files and streams, folders of images."""

from __future__ import annotations

from pathlib import Path

from calib_core.connectors.frame import FrameSource, VideoSourceError


def open_opencv(spec: str, options: dict) -> FrameSource:
    """``0``, ``1``...: an OpenCV device (V4L2 on Linux); ``opencv://0`` says the same."""
    from calib_core.video.opencv_source import OpenCVSource

    index = spec.split("://", 1)[-1]
    if not index.isdigit():
        raise VideoSourceError(f"camera {spec!r}: an OpenCV device is a number (0, 1, ...)")
    return OpenCVSource(int(index))


def open_file(spec: str, options: dict) -> FrameSource:
    """A video file (``clip.mp4`` or ``file:///path/clip.mp4``), played once."""
    from calib_core.video.opencv_source import OpenCVSource

    path = Path(spec.split("://", 1)[-1]) if spec.startswith("file://") else Path(spec)
    if not path.is_file():
        raise VideoSourceError(f"camera {spec!r}: no such video file")
    return OpenCVSource(str(path))


def open_stream(spec: str, options: dict) -> FrameSource:
    """An RTSP or HTTP stream through OpenCV's FFmpeg back end, opened again when it drops (``timeout_s``,
    ``reopen_every_s`` from the ``site:`` section's camera options)."""
    from calib_core.connectors.options import number_option
    from calib_core.video.stream_source import StreamSource

    options = dict(options or {})
    unknown = set(options) - {"timeout_s", "reopen_every_s"}
    if unknown:
        raise VideoSourceError(
            f"camera {spec!r}: unknown option(s) {', '.join(sorted(unknown))}; known: reopen_every_s, timeout_s"
        )
    from calib_core.connectors.link_types import LinkError

    try:
        timeout_s = number_option(options, "timeout_s", 5.0, 0.1, 600.0, spec)
        reopen_every_s = number_option(options, "reopen_every_s", 1.0, 0.05, 600.0, spec)
    except LinkError as exc:
        raise VideoSourceError(f"camera {exc}") from None
    return StreamSource(spec, timeout_s=timeout_s, reopen_every_s=reopen_every_s)


def open_folder(spec: str, options: dict) -> FrameSource:
    """A folder of images, played in a loop (``folder:///path`` or the folder's path)."""
    from calib_core.video.folder_source import ImageFolderSource

    path = spec.split("://", 1)[-1] if spec.startswith("folder://") else spec
    return ImageFolderSource(path, loop=bool(options.get("loop", True)))
