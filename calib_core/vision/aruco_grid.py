"""ArUco grid boards: ``aruco:COLSxROWS:MARKER_MM:GAP_MM:DICTIONARY`` (OpenCV's ``GridBoard``: markers
``MARKER_MM`` wide, ``GAP_MM`` apart, ids from 0 row by row). Every marker gives its four corners:
point ``4 * k + c`` is corner ``c`` (top-left, top-right, bottom-right, bottom-left) of the board's
k-th marker. Markers the first pass misses are recovered from the board's layout when
``refine_markers`` is on (the default).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.vision.target_detection import DetectorSettings, TargetDetection
from calib_core.vision.target_spec import dictionary, grid, length_mm, usage_error


@dataclass(frozen=True)
class ArucoGridSpec:
    cols: int
    rows: int
    marker_mm: float
    gap_mm: float
    dictionary: str

    kind = "aruco"
    unambiguous = True

    @classmethod
    def parse(cls, text: str) -> ArucoGridSpec:
        parts = text.split(":")
        if len(parts) != 5 or parts[0] != "aruco":
            raise usage_error(text)
        cols, rows = grid(text, parts[1], 1, "markers")
        marker = length_mm(text, parts[2], "marker")
        gap = length_mm(text, parts[3], "gap")
        dictionary(text, parts[4], cols * rows)
        return cls(cols, rows, marker, gap, parts[4])

    def __str__(self) -> str:
        return f"aruco:{self.cols}x{self.rows}:{self.marker_mm:g}:{self.gap_mm:g}:{self.dictionary}"

    @property
    def size_mm(self) -> tuple[float, float]:
        return (
            self.cols * (self.marker_mm + self.gap_mm) - self.gap_mm,
            self.rows * (self.marker_mm + self.gap_mm) - self.gap_mm,
        )

    def board(self) -> cv2.aruco.GridBoard:
        return cv2.aruco.GridBoard(
            (self.cols, self.rows),
            self.marker_mm,
            self.gap_mm,
            cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary)),
        )

    def corners_mm(self) -> np.ndarray:
        """Marker corners (4 * cols * rows, 3), marker by marker."""
        return np.asarray(self.board().getObjPoints(), dtype=float).reshape(-1, 3)

    def image(self, px_per_mm: float = 4.0) -> np.ndarray:
        w, h = self.size_mm
        return self.board().generateImage(
            (int(round(w * px_per_mm)), int(round(h * px_per_mm))), marginSize=0, borderBits=1
        )

    def detector(self, settings: DetectorSettings | None = None):
        settings = settings or DetectorSettings()
        params = settings.aruco
        if settings.source is None:
            # An ArUco grid's points are the marker corners themselves: refine them to sub-pixel unless
            # a settings file says otherwise (a ChArUco board refines its chessboard corners instead).
            params = cv2.aruco.DetectorParameters()
            params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        board = self.board()
        detector = cv2.aruco.ArucoDetector(board.getDictionary(), params, cv2.aruco.RefineParameters())
        first_id = int(np.min(board.getIds()))

        def detect(grey: np.ndarray) -> TargetDetection:
            corners, ids, rejected = detector.detectMarkers(grey)
            if settings.refine_markers and ids is not None and len(ids):
                corners, ids, _, _ = detector.refineDetectedMarkers(grey, board, corners, ids, rejected)
            if ids is None or len(ids) == 0:
                return TargetDetection(np.zeros((0, 2)), np.zeros(0, dtype=int), 0)
            ids = ids.ravel().astype(int) - first_id
            keep = (ids >= 0) & (ids < self.cols * self.rows)
            points = (
                np.concatenate([c.reshape(4, 2) for c, k in zip(corners, keep) if k])
                if keep.any()
                else np.zeros((0, 2))
            )
            point_ids = (4 * ids[keep][:, None] + np.arange(4)[None, :]).ravel()
            return TargetDetection(points.astype(np.float64), point_ids, int(len(ids)))

        return detect
