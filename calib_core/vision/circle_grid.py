"""Grids of circles: ``circles:COLSxROWS:SPACING_MM[:asymmetric]``, as OpenCV's ``findCirclesGrid``
counts them (an asymmetric grid's rows are offset by half a step; ``SPACING_MM`` is then the distance
between neighbouring circles of one row divided by two, OpenCV's convention).

The detected centre is the centre of the imaged blob, which is not the image of the circle's centre
under perspective: the bias grows with the circles' size and the tilt (about 0.1-0.3 px for the usual
targets). Blob detection follows ``circle_blobs`` of the detector settings.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.vision.target_detection import DetectorSettings, TargetDetection
from calib_core.vision.target_spec import grid, length_mm, usage_error


@dataclass(frozen=True)
class CircleGridSpec:
    """``cols`` circles per row, ``rows`` rows, ``spacing_mm`` apart; dark circles on white, one
    spacing of margin round the grid."""

    cols: int
    rows: int
    spacing_mm: float
    asymmetric: bool = False

    kind = "circles"
    unambiguous = False

    @classmethod
    def parse(cls, text: str) -> CircleGridSpec:
        parts = text.split(":")
        if parts[0] != "circles" or len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "asymmetric"):
            raise usage_error(text)
        cols, rows = grid(text, parts[1], 2, "circles")
        return cls(cols, rows, length_mm(text, parts[2], "spacing"), len(parts) == 4)

    def __str__(self) -> str:
        return f"circles:{self.cols}x{self.rows}:{self.spacing_mm:g}" + (":asymmetric" if self.asymmetric else "")

    @property
    def radius_mm(self) -> float:
        return 0.3 * self.spacing_mm

    @property
    def size_mm(self) -> tuple[float, float]:
        span_x = (2 * self.cols - 1 if self.asymmetric else self.cols - 1) * self.spacing_mm
        return span_x + 2 * self.spacing_mm, (self.rows - 1) * self.spacing_mm + 2 * self.spacing_mm

    def corners_mm(self) -> np.ndarray:
        """Circle centres (cols * rows, 3) in OpenCV's order (row by row)."""
        j, i = np.mgrid[0 : self.rows, 0 : self.cols]
        i, j = i.ravel(), j.ravel()
        x = (2 * i + j % 2) if self.asymmetric else i
        return np.column_stack([(x + 1) * self.spacing_mm, (j + 1) * self.spacing_mm, np.zeros(i.size)])

    def image(self, px_per_mm: float = 4.0) -> np.ndarray:
        w, h = self.size_mm
        out = np.full((int(round(h * px_per_mm)), int(round(w * px_per_mm))), 255, np.uint8)
        shift = 4
        for x, y, _ in self.corners_mm():
            centre = (
                int(round((x * px_per_mm - 0.5) * (1 << shift))),
                int(round((y * px_per_mm - 0.5) * (1 << shift))),
            )
            cv2.circle(out, centre, int(round(self.radius_mm * px_per_mm * (1 << shift))), 0, -1, cv2.LINE_AA, shift)
        return out

    def detector(self, settings: DetectorSettings | None = None):
        settings = settings or DetectorSettings()
        blobs = cv2.SimpleBlobDetector_create(settings.circle_blobs)
        flags = cv2.CALIB_CB_ASYMMETRIC_GRID if self.asymmetric else cv2.CALIB_CB_SYMMETRIC_GRID
        size = (self.cols, self.rows)

        def detect(grey: np.ndarray) -> TargetDetection:
            found, centres = cv2.findCirclesGrid(grey, size, flags=flags, blobDetector=blobs)
            if not found:
                found, centres = cv2.findCirclesGrid(
                    grey, size, flags=flags | cv2.CALIB_CB_CLUSTERING, blobDetector=blobs
                )
            if not found:
                return TargetDetection(np.zeros((0, 2)), np.zeros(0, dtype=int), len(blobs.detect(grey)))
            return TargetDetection(
                centres.reshape(-1, 2).astype(np.float64), np.arange(self.cols * self.rows), self.cols * self.rows
            )

        return detect
