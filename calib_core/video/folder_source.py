"""Frames from a folder of images, in file-name order (a recorded sequence, or board views)."""

from __future__ import annotations

import time
from pathlib import Path

from calib_core.errors import FileFormatError
from calib_core.image_files import read_image
from calib_core.connectors.frame import Frame, FrameSource, VideoSourceError

SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"}


class ImageFolderSource(FrameSource):
    """Each image once, at ``fps``; ``loop`` starts again after the last one."""

    def __init__(self, folder: str | Path, fps: float = 5.0, loop: bool = False):
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise VideoSourceError(f"{self.folder}: no such folder")
        self.files = sorted(p for p in self.folder.iterdir() if p.suffix.lower() in SUFFIXES)
        if not self.files:
            raise VideoSourceError(f"{self.folder}: no images ({', '.join(sorted(SUFFIXES))})")
        self.description = f"images in {self.folder}"
        self._fps = float(fps)
        self.loop = loop
        self._index = 0

    @property
    def fps(self) -> float:
        return self._fps

    def read(self) -> Frame | None:
        if self._index >= len(self.files):
            if not self.loop:
                return None
        path = self.files[self._index % len(self.files)]
        try:
            rgb = read_image(path)
        except FileFormatError as exc:
            raise VideoSourceError(str(exc)) from None
        frame = Frame(rgb, self._index, time.monotonic(), self._index / self._fps if self._fps else None)
        self._index += 1
        return frame
