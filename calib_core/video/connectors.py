"""The built-in camera connectors: OpenCV devices, video files and streams, folders of images."""

from __future__ import annotations

from pathlib import Path

from calib_core.video.frame import FrameSource, VideoSourceError


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
    """An RTSP or HTTP stream through OpenCV's FFmpeg back end."""
    from calib_core.video.opencv_source import OpenCVSource

    return OpenCVSource(spec)


def open_folder(spec: str, options: dict) -> FrameSource:
    """A folder of images, played in a loop (``folder:///path`` or the folder's path)."""
    from calib_core.video.folder_source import ImageFolderSource

    path = spec.split("://", 1)[-1] if spec.startswith("folder://") else spec
    return ImageFolderSource(path, loop=bool(options.get("loop", True)))
