"""The camera frames of a recording as a seekable sequence, whether they were recorded as H.264
video or as JPEG images: what the window's replay timeline and the headless tools show."""

from __future__ import annotations

import bisect

import numpy as np

from calib_core.recording.reader import RecordedMessage, RecordingContents, decode_frame
from calib_core.recording.schemas import FRAME_TOPIC, VIDEO_TOPIC
from calib_core.recording.video_codec import H264Decoder, is_keyframe


class FrameTrack:
    """Frames in recording order. ``times_s`` (n,): seconds since the recording's first message.

    ``image(k)`` decodes frame ``k`` (RGB, (h, w, 3) uint8): sequential access decodes one packet
    per frame; a jump decodes from the keyframe before ``k`` (at most a keyframe interval)."""

    def __init__(self, contents: RecordingContents):
        video = contents.topic(VIDEO_TOPIC)
        self.messages: list[RecordedMessage] = video or contents.topic(FRAME_TOPIC)
        self.is_video = bool(video)
        t0 = contents.messages[0].log_time_ns if contents.messages else 0
        self.times_s = np.array([(m.log_time_ns - t0) / 1e9 for m in self.messages])
        self.keyframes = (
            [k for k, m in enumerate(self.messages) if is_keyframe(m.payload["data"])]
            if self.is_video
            else list(range(len(self.messages)))
        )
        self._decoder: H264Decoder | None = None
        self._decoded = -1
        self._last: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.messages)

    def index_at(self, t_s: float) -> int:
        """The last frame at or before ``t_s`` (s since the start); 0 before the first."""
        return max(0, bisect.bisect_right(self.times_s, t_s) - 1)

    def image(self, k: int) -> np.ndarray | None:
        """Frame ``k``; ``None`` when no keyframe precedes it (a recording cut before its first IDR)."""
        if not 0 <= k < len(self.messages):
            raise IndexError(f"frame {k} of a recording with {len(self.messages)} frames")
        if not self.is_video:
            return decode_frame(self.messages[k].payload)
        if k == self._decoded:
            return self._last
        if self._decoder is None or not (self._decoded < k and k - self._decoded <= self._gap_to_keyframe(k)):
            start = self._keyframe_before(k)
            if start is None:
                return None
            self._decoder, self._decoded = H264Decoder(), start - 1
        image = None
        for j in range(self._decoded + 1, k + 1):
            image = self._decoder.decode(self.messages[j].payload["data"])
        self._decoded, self._last = k, image
        return image

    def _keyframe_before(self, k: int) -> int | None:
        i = bisect.bisect_right(self.keyframes, k) - 1
        return self.keyframes[i] if i >= 0 else None

    def _gap_to_keyframe(self, k: int) -> int:
        # Decoding on from the current frame beats restarting at the keyframe only when it is nearer.
        start = self._keyframe_before(k)
        return k - start if start is not None else k + 1
