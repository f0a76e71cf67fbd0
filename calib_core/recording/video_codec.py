"""H.264 for recorded camera frames, as Foxglove plays it: Annex B, one frame per packet, no
B-frames, an IDR with its SPS/PPS every ``keyframe_interval`` frames (for scrubbing).

JPEG frames cost ~450 kB each at 1280 x 960; a camera on a robot that stands still most of the
session compresses 30-100 times better as video. PyAV's FFmpeg (libx264) does the coding.
"""

from __future__ import annotations

from fractions import Fraction

import av
import numpy as np

DEFAULT_CRF = 30
"""x264's constant rate factor: 30 keeps corners and edges crisp enough to pick on (the sensor
noise goes first) at ~2 MB/min for the simulated camera."""


class H264Encoder:
    """Encode RGB frames (h, w, 3) uint8 of one size; ``encode`` gives that frame's Annex B packet."""

    def __init__(
        self,
        width: int,
        height: int,
        *,
        fps: float = 15.0,
        crf: int = DEFAULT_CRF,
        keyframe_interval: int = 30,
        preset: str = "veryfast",
    ):
        if width % 2 or height % 2:
            raise ValueError(f"H.264 (4:2:0) needs an even frame size, got {width} x {height}")
        self.width, self.height = width, height
        ctx = av.CodecContext.create("libx264", "w")
        ctx.width, ctx.height, ctx.pix_fmt = width, height, "yuv420p"
        ctx.time_base = Fraction(1, 1000)
        ctx.framerate = Fraction(round(fps * 1000), 1000)
        ctx.gop_size = keyframe_interval
        # zerolatency: no lookahead and no frame buffering, so every frame's packet comes out at
        # once and a recording cut off by a crash loses no frame before the cut; bf=0: Foxglove
        # cannot play B-frames; repeat-headers: SPS/PPS in front of every IDR.
        ctx.options = {
            "preset": preset,
            "tune": "zerolatency",
            "crf": str(crf),
            "bf": "0",
            "x264-params": f"keyint={keyframe_interval}:min-keyint={keyframe_interval}:scenecut=0:repeat-headers=1",
        }
        self._ctx = ctx
        self._pts = 0

    def encode(self, image_rgb: np.ndarray) -> bytes:
        if image_rgb.shape[:2] != (self.height, self.width):
            raise ValueError(
                f"frame is {image_rgb.shape[1]} x {image_rgb.shape[0]}, the video is {self.width} x {self.height}"
            )
        frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(image_rgb), format="rgb24")
        frame.pts = self._pts
        self._pts += 1
        return b"".join(bytes(p) for p in self._ctx.encode(frame))

    def flush(self) -> bytes:
        return b"".join(bytes(p) for p in self._ctx.encode(None))


def nal_unit_types(annexb: bytes) -> list[int]:
    """The NAL unit types of an Annex B byte stream, in order (5 = IDR slice, 7 = SPS, 8 = PPS)."""
    types = []
    i, n = 0, len(annexb)
    while True:
        i = annexb.find(b"\x00\x00\x01", i)
        if i < 0 or i + 3 >= n:
            return types
        types.append(annexb[i + 3] & 0x1F)
        i += 3


def is_keyframe(annexb: bytes) -> bool:
    """True when the packet can be decoded on its own: an IDR slice with its SPS."""
    types = nal_unit_types(annexb)
    return 5 in types and 7 in types


class H264Decoder:
    """Decode Annex B packets in order; ``decode`` gives the frame's RGB image or ``None`` when the
    packet made no picture (a delta frame without its keyframe)."""

    def __init__(self) -> None:
        self._ctx = av.CodecContext.create("h264", "r")

    def decode(self, annexb: bytes) -> np.ndarray | None:
        try:
            frames = self._ctx.decode(av.Packet(annexb))
        except av.error.InvalidDataError:
            return None
        return frames[-1].to_ndarray(format="rgb24") if frames else None
