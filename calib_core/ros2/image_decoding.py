"""``sensor_msgs/Image`` and ``CompressedImage`` to an RGB array, by the encodings ROS 2's
``sensor_msgs/image_encodings.hpp`` names (the ones cameras send)."""

from __future__ import annotations

import cv2
import numpy as np

from calib_core.connectors.frame import VideoSourceError

_BAYER = {
    "bayer_rggb8": cv2.COLOR_BayerRGGB2RGB,
    "bayer_bggr8": cv2.COLOR_BayerBGGR2RGB,
    "bayer_gbrg8": cv2.COLOR_BayerGBRG2RGB,
    "bayer_grbg8": cv2.COLOR_BayerGRBG2RGB,
}
_CHANNELS = {
    "rgb8": 3,
    "bgr8": 3,
    "rgba8": 4,
    "bgra8": 4,
    "mono8": 1,
    "8UC1": 1,
    "8UC3": 3,
    "mono16": 1,
    "16UC1": 1,
    **{k: 1 for k in _BAYER},
}
SUPPORTED = tuple(_CHANNELS)


def image_to_rgb(message, where: str) -> np.ndarray:
    """(h, w, 3) uint8 RGB of a ``sensor_msgs/Image``; :class:`VideoSourceError` names ``where`` and the fault."""
    encoding = str(message.encoding)
    if encoding not in _CHANNELS:
        raise VideoSourceError(
            f"{where}: image encoding {encoding!r} is not supported (supported: {', '.join(SUPPORTED)})"
        )
    channels = _CHANNELS[encoding]
    depth = 2 if encoding in ("mono16", "16UC1") else 1
    h, w, step = int(message.height), int(message.width), int(message.step)
    data = message.data if isinstance(message.data, (bytes, bytearray)) else bytes(message.data)
    if h <= 0 or w <= 0 or step < w * channels * depth or len(data) < h * step:
        raise VideoSourceError(
            f"{where}: an image of {w} x {h} with step {step} needs {h * step} bytes, got {len(data)}"
        )
    rows = np.frombuffer(data, np.uint8, count=h * step).reshape(h, step)[:, : w * channels * depth]
    if depth == 2:
        values = rows.view(">u2" if message.is_bigendian else "<u2").reshape(h, w)
        grey = (values >> 8).astype(np.uint8)
        return cv2.cvtColor(grey, cv2.COLOR_GRAY2RGB)
    pixels = rows.reshape(h, w, channels) if channels > 1 else rows.reshape(h, w)
    if encoding in _BAYER:
        return cv2.cvtColor(np.ascontiguousarray(pixels), _BAYER[encoding])
    if channels == 1:
        return cv2.cvtColor(np.ascontiguousarray(pixels), cv2.COLOR_GRAY2RGB)
    if encoding in ("bgr8", "8UC3"):
        return cv2.cvtColor(pixels, cv2.COLOR_BGR2RGB)
    if encoding == "bgra8":
        return cv2.cvtColor(pixels, cv2.COLOR_BGRA2RGB)
    if encoding == "rgba8":
        return cv2.cvtColor(pixels, cv2.COLOR_RGBA2RGB)
    return np.ascontiguousarray(pixels)


def compressed_to_rgb(message, where: str, max_pixels: int = 50_000_000) -> np.ndarray:
    """(h, w, 3) uint8 RGB of a ``sensor_msgs/CompressedImage`` (JPEG or PNG); the size is checked before decoding."""
    data = np.frombuffer(bytes(message.data), np.uint8)
    header = _size_of(bytes(message.data[:32]))
    if header is not None and header[0] * header[1] > max_pixels:
        raise VideoSourceError(
            f"{where}: a compressed image of {header[0]} x {header[1]} px is over the limit of {max_pixels} px"
        )
    bgr = cv2.imdecode(data, cv2.IMREAD_COLOR)
    if bgr is None:
        raise VideoSourceError(
            f"{where}: a {message.format or 'compressed'} image that does not decode ({len(data)} bytes)"
        )
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def _size_of(head: bytes) -> tuple[int, int] | None:
    """(width, height) of a PNG from its header (JPEG sizes are bounded by the message's size)."""
    if head[:8] == b"\x89PNG\r\n\x1a\n" and len(head) >= 24:
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    return None
