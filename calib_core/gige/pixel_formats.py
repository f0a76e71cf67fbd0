"""GenICam pixel formats (PFNC codes, as Aravis reports them) to an RGB array."""

from __future__ import annotations

import cv2
import numpy as np

from calib_core.connectors.frame import VideoSourceError

# PFNC codes: Mono8, Mono16, RGB8, BGR8 and the 8-bit Bayer patterns.
MONO8, MONO16, RGB8, BGR8 = 0x01080001, 0x01100007, 0x02180014, 0x02180015
BAYER = {
    0x01080008: cv2.COLOR_BayerGRBG2RGB,
    0x01080009: cv2.COLOR_BayerRGGB2RGB,
    0x0108000A: cv2.COLOR_BayerGBRG2RGB,
    0x0108000B: cv2.COLOR_BayerBGGR2RGB,
}
NAMES = {
    MONO8: "Mono8",
    MONO16: "Mono16",
    RGB8: "RGB8",
    BGR8: "BGR8",
    0x01080008: "BayerGR8",
    0x01080009: "BayerRG8",
    0x0108000A: "BayerGB8",
    0x0108000B: "BayerBG8",
}


def to_rgb(data: bytes, width: int, height: int, pixel_format: int, where: str) -> np.ndarray:
    """(height, width, 3) uint8 RGB of one image; :class:`VideoSourceError` names ``where`` and the format."""
    channels = 3 if pixel_format in (RGB8, BGR8) else (2 if pixel_format == MONO16 else 1)
    need = width * height * channels
    if pixel_format not in NAMES:
        raise VideoSourceError(
            f"{where}: pixel format 0x{pixel_format:08X} is not supported (supported: {', '.join(NAMES.values())})"
        )
    if width <= 0 or height <= 0 or len(data) < need:
        raise VideoSourceError(
            f"{where}: a {NAMES[pixel_format]} image of {width} x {height} needs {need} bytes, got {len(data)}"
        )
    raw = np.frombuffer(data, np.uint8, count=need)
    if pixel_format == RGB8:
        return raw.reshape(height, width, 3).copy()
    if pixel_format == BGR8:
        return cv2.cvtColor(raw.reshape(height, width, 3), cv2.COLOR_BGR2RGB)
    if pixel_format == MONO16:
        return cv2.cvtColor((raw.view("<u2").reshape(height, width) >> 8).astype(np.uint8), cv2.COLOR_GRAY2RGB)
    grey = raw.reshape(height, width)
    if pixel_format in BAYER:
        return cv2.cvtColor(grey, BAYER[pixel_format])
    return cv2.cvtColor(grey, cv2.COLOR_GRAY2RGB)
