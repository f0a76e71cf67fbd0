"""Image files beyond their limits: each is refused by name, before decoding, with the limit; none gives
a traceback or allocates gigabytes. The cases are the held-out fuzzing's findings."""

from __future__ import annotations

import os
import struct
import subprocess
import sys
import zlib

import cv2
import numpy as np
import pytest

from calib_core.errors import FileFormatError
from calib_core.image_files import MAX_IMAGE_PIXELS, image_size, read_image


def _png_claiming(path, width: int, height: int) -> None:
    """A PNG whose header claims ``width`` x ``height`` (its pixel data is a few bytes)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b"")
    )


@pytest.mark.parametrize("width, height", [(100_000, 100_000), (32_767, 32_767), (MAX_IMAGE_PIXELS // 1000 + 1, 1000)])
def test_an_image_over_the_limit_is_refused_from_its_header(tmp_path, width, height):
    path = tmp_path / "huge.png"
    _png_claiming(path, width, height)
    assert image_size(path) == (width, height)  # read from the header alone
    with pytest.raises(FileFormatError, match=rf"{width} x {height} px is over the limit of 100 megapixels") as info:
        read_image(path)
    assert info.value.path == path


def test_files_that_are_no_images_are_refused_by_name(tmp_path):
    text = tmp_path / "notes.png"
    text.write_text("not a picture")
    cut = tmp_path / "cut.png"
    ok, png = cv2.imencode(".png", np.full((40, 60, 3), 90, np.uint8))
    cut.write_bytes(png.tobytes()[:30])
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    for path, why in (
        (text, "not an image OpenCV can read"),
        (cut, "not an image OpenCV can read"),
        (fifo, "not a regular file"),
        (tmp_path / "missing.png", "no such image file"),
    ):
        with pytest.raises(FileFormatError, match=why):
            read_image(path)
    good = tmp_path / "good.png"
    good.write_bytes(png.tobytes())
    image = read_image(good)
    assert image.shape == (40, 60, 3) and read_image(good, grey=True).shape == (40, 60)


def test_the_command_line_says_one_error_line_for_a_huge_image(tmp_path):
    folder = tmp_path / "views"
    folder.mkdir()
    _png_claiming(folder / "huge.png", 100_000, 100_000)
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "calibrate-intrinsics", str(folder), "--out", str(tmp_path / "i.yaml")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert (
        run.stderr.strip()
        == f"error: {folder / 'huge.png'}: an image of 100000 x 100000 px is over the limit of 100 megapixels"
    )
    assert not (tmp_path / "i.yaml").exists()
