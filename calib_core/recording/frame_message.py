"""A camera frame as the message a recording keeps: H.264 (``foxglove.CompressedVideo``, protobuf)
or JPEG (``foxglove.CompressedImage``, JSON), stamped with its capture time."""

from __future__ import annotations

import base64
import json

import cv2
import numpy as np

from calib_core.recording.schemas import FRAME_TOPIC, VIDEO_TOPIC
from calib_core.recording.video_codec import DEFAULT_CRF, H264Encoder

FRAME_FORMATS = ("h264", "jpeg")


class FrameEncoder:
    """Turns RGB frames (h, w, 3) uint8 (or grey (h, w)) into ``(topic, bytes)`` of ``frames`` format;
    the H.264 stream is restarted when the frame size changes. Not thread-safe: one writer owns it."""

    def __init__(self, frames: str = "h264", *, fps: float = 15.0, crf: int = DEFAULT_CRF, jpeg_quality: int = 90):
        if frames not in FRAME_FORMATS:
            raise ValueError(f"frames must be one of {', '.join(FRAME_FORMATS)}, got {frames!r}")
        self.frames, self.fps, self.crf, self.jpeg_quality = frames, fps, crf, jpeg_quality
        self._h264: H264Encoder | None = None

    def encode(self, image: np.ndarray, capture_ns: int, t_host_s: float, frame_id: str) -> tuple[str, bytes] | None:
        """The message of one frame; ``None`` when the encoder holds it back (no packet yet)."""
        if image.ndim == 2 or image.shape[2] == 1:  # a monochrome camera: recorded as grey RGB
            image = np.repeat(image.reshape(image.shape[0], image.shape[1], 1), 3, axis=2)
        if self.frames == "jpeg":
            ok, jpeg = cv2.imencode(
                ".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality]
            )
            if not ok:
                raise ValueError("a frame could not be JPEG-encoded")
            payload = {
                "timestamp": {"sec": capture_ns // 10**9, "nsec": capture_ns % 10**9},
                "frame_id": frame_id,
                "format": "jpeg",
                "data": base64.b64encode(jpeg.tobytes()).decode(),
                "t_host_s": t_host_s,
            }
            return FRAME_TOPIC, json.dumps(payload, separators=(",", ":")).encode()
        from foxglove_schemas_protobuf.CompressedVideo_pb2 import CompressedVideo

        h, w = image.shape[:2]
        image = image[: h - h % 2, : w - w % 2]  # 4:2:0 needs even sizes: drop an odd last row/column
        if self._h264 is None or (self._h264.height, self._h264.width) != image.shape[:2]:
            self._h264 = H264Encoder(image.shape[1], image.shape[0], fps=self.fps, crf=self.crf)
        packet = self._h264.encode(image)
        if not packet:
            return None
        message = CompressedVideo(frame_id=frame_id, data=packet, format="h264")
        message.timestamp.FromNanoseconds(capture_ns)
        return VIDEO_TOPIC, message.SerializeToString()
