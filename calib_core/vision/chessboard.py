"""Chessboards: ``chessboard:COLSxROWS:SQUARE_MM``, counted in inner corners as OpenCV counts them
(OpenCV's sample ``left01.jpg`` is ``chessboard:9x6:25``).

Detected with ``findChessboardCornersSB`` (the sector-based detector: sub-pixel corners, robust to
blur and to lighting), falling back to the classic ``findChessboardCorners`` + ``cornerSubPix``.
The whole board must be seen. A board of odd by even squares (inner corners odd by even: OpenCV's
``left01.jpg`` board of 9 x 6) looks different turned half a turn, since its colours swap: the square
diagonally out from the first corner is black, and a detection that starts at the other end is turned
round, so the first corner is known and the board serves a hand-eye or robot calibration. A board of
odd by odd or even by even squares (a square one, too) looks the same turned: its detections fix the
corners but not which is the first, fine for the intrinsics only.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.vision.target_detection import DetectorSettings, TargetDetection
from calib_core.vision.target_spec import grid, length_mm, usage_error

_SUBPIX = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 40, 0.001)


@dataclass(frozen=True)
class ChessboardSpec:
    """``cols`` x ``rows`` inner corners, ``square_mm`` apart; the sheet has one more square each way."""

    cols: int
    rows: int
    square_mm: float

    kind = "chessboard"

    @property
    def unambiguous(self) -> bool:
        """Whether a detection fixes which corner is the first: odd by even squares (a half turn swaps the colours)."""
        return (self.cols + self.rows) % 2 == 1

    @classmethod
    def parse(cls, text: str) -> ChessboardSpec:
        parts = text.split(":")
        if len(parts) != 3 or parts[0] != "chessboard":
            raise usage_error(text)
        cols, rows = grid(text, parts[1], 2, "inner corners")
        return cls(cols, rows, length_mm(text, parts[2], "square"))

    def __str__(self) -> str:
        return f"chessboard:{self.cols}x{self.rows}:{self.square_mm:g}"

    @property
    def size_mm(self) -> tuple[float, float]:
        return (self.cols + 1) * self.square_mm, (self.rows + 1) * self.square_mm

    def corners_mm(self) -> np.ndarray:
        """Inner corners (cols * rows, 3), row by row, the first one square in from the sheet's corner."""
        j, i = np.mgrid[0 : self.rows, 0 : self.cols]
        return np.column_stack([(i.ravel() + 1) * self.square_mm, (j.ravel() + 1) * self.square_mm, np.zeros(i.size)])

    def image(self, px_per_mm: float = 4.0) -> np.ndarray:
        w, h = self.size_mm
        width, height = int(round(w * px_per_mm)), int(round(h * px_per_mm))
        x = (np.arange(width) + 0.5) / px_per_mm // self.square_mm
        y = (np.arange(height) + 0.5) / px_per_mm // self.square_mm
        return np.where((x[None, :] + y[:, None]) % 2 == 0, 0, 255).astype(np.uint8)

    def detector(self, settings: DetectorSettings | None = None):
        size = (self.cols, self.rows)

        def detect(grey: np.ndarray) -> TargetDetection:
            found, corners = cv2.findChessboardCornersSB(
                grey, size, flags=cv2.CALIB_CB_EXHAUSTIVE | cv2.CALIB_CB_ACCURACY
            )
            if not found:
                found, corners = cv2.findChessboardCorners(
                    grey, size, flags=cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
                )
                if found:
                    corners = cv2.cornerSubPix(grey, corners, (5, 5), (-1, -1), _SUBPIX)
            if not found:
                return TargetDetection(np.zeros((0, 2)), np.zeros(0, dtype=int), 0)
            corners = corners.reshape(-1, 2).astype(np.float64)
            if self.unambiguous and _turned_round(grey, corners, self.cols):
                corners = corners[::-1].copy()
            return TargetDetection(corners, np.arange(self.cols * self.rows), self.cols * self.rows)

        return detect


def _turned_round(grey: np.ndarray, corners_px: np.ndarray, cols: int) -> bool:
    """Whether a detection (n, 2) px of a board of odd by even squares starts at the far end: the squares diagonal to
    the first corner (outward and inward) are the sheet's black ones, the two beside them white; turned round, the
    colours there are the other way."""
    first, along, down = corners_px[0], corners_px[1] - corners_px[0], corners_px[cols] - corners_px[0]
    blurred = cv2.GaussianBlur(grey, (0, 0), 1.0).astype(np.float32)

    def shade(a: float, b: float) -> float:
        p = (first + a * along + b * down).astype(np.float32).reshape(1, 1, 2)
        return float(cv2.remap(blurred, p[..., 0], p[..., 1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)[0, 0])

    dark = shade(-0.5, -0.5) + shade(0.5, 0.5)
    light = shade(0.5, -0.5) + shade(-0.5, 0.5)
    return dark > light
