"""Reading an image file with its limits checked first: a PNG that claims 100000 x 100000 pixels would
make OpenCV allocate 30 GB (or fail with an assertion and a traceback); its size is read from the header before
anything is decoded, and a file that is no image, or too large, is an error naming the file and the limit.
"""

from __future__ import annotations

import threading
import warnings
from pathlib import Path

import numpy as np

from calib_core.errors import FileFormatError

MAX_IMAGE_PIXELS = 100_000_000
"""The largest image read (pixels): 100 megapixels, ten times a 4K frame; 300 MB once decoded as RGB."""

_PILLOW_LIMIT = threading.Lock()


def image_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from the file's header alone (Pillow reads headers lazily), ``None`` when Pillow does not know
    the format (OpenCV may still read it)."""
    from PIL import Image, UnidentifiedImageError

    with _PILLOW_LIMIT, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Pillow's own "decompression bomb" warning: the limit is said by the caller
        before, Image.MAX_IMAGE_PIXELS = Image.MAX_IMAGE_PIXELS, None  # a header is only read here, never decoded
        try:
            with Image.open(path) as image:
                return int(image.width), int(image.height)
        except (UnidentifiedImageError, OSError, ValueError):
            return None
        finally:
            Image.MAX_IMAGE_PIXELS = before


def read_image(
    path: str | Path, *, grey: bool = False, max_pixels: int = MAX_IMAGE_PIXELS, where: str | None = None
) -> np.ndarray:
    """The image at ``path``: (h, w, 3) uint8 RGB, or (h, w) uint8 with ``grey``. :class:`FileFormatError` naming the
    file (and ``where``, a row of a list that named it) for a file that is missing, not a regular file, over
    ``max_pixels`` by its header, or not an image OpenCV can decode."""
    import cv2

    path = Path(path)
    if not path.is_file():
        raise FileFormatError(path, "no such image file (or not a regular file)", where)
    size = image_size(path)
    if size is not None and size[0] * size[1] > max_pixels:
        raise FileFormatError(
            path, f"an image of {size[0]} x {size[1]} px is over the limit of {max_pixels / 1e6:g} megapixels", where
        )
    try:
        image = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE if grey else cv2.IMREAD_COLOR)
    except cv2.error as exc:  # OpenCV's own limits (a header Pillow could not read)
        raise FileFormatError(
            path, f"not an image OpenCV can read: {str(exc).strip().splitlines()[-1]}", where
        ) from None
    if image is None:
        raise FileFormatError(path, "not an image OpenCV can read", where)
    return image if grey else cv2.cvtColor(image, cv2.COLOR_BGR2RGB)
