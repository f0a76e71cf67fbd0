"""Video sources: OpenCV devices, files and URLs, image folders, recordings, the simulated camera."""

from calib_core.connectors.frame import Frame, FrameSource, VideoSourceError

__all__ = ["Frame", "FrameSource", "VideoSourceError"]
