"""Images for the intrinsics calibration: a folder of images or every n-th frame of a video."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np

from calib_core.errors import FileFormatError
from calib_core.image_files import read_image

IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"}


def folder_images(folder: Path) -> Iterator[tuple[str, np.ndarray]]:
    """(name, RGB image) of every image file in ``folder``, by name; unreadable files raise naming them."""
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
    if not files:
        raise FileFormatError(folder, f"no images ({', '.join(sorted(IMAGE_SUFFIXES))}) in this folder")
    for p in files:
        yield p.name, read_image(p)  # its size checked from the header before decoding


def video_frames(path: Path, every: int = 15) -> Iterator[tuple[str, np.ndarray]]:
    """(name, RGB frame) of every ``every``-th frame of a video file."""
    cap = cv2.VideoCapture(str(path))
    if not cap.isOpened():
        raise FileFormatError(path, "not a video OpenCV can read")
    k = 0
    try:
        while True:
            ok, bgr = cap.read()
            if not ok:
                break
            if k % every == 0:
                yield f"frame_{k:05d}", cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
            k += 1
    finally:
        cap.release()
