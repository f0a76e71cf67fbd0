"""Calibration targets: ChArUco boards here, and :func:`parse_board` for every kind.

Every target has one frame: origin at the printed sheet's top-left corner, x to the right, y down the
printed image, z into it (mm). ``corners_mm()`` gives its points (n, 3) in that frame, ``detect(grey,
settings)`` a :class:`~calib_core.vision.target_detection.TargetDetection` whose ids index them,
``image(px_per_mm)`` the printable sheet and ``size_mm`` its size; ``unambiguous`` says whether a
detection fixes the target's orientation (a ChArUco or ArUco board does; a chessboard or a grid of
circles looks the same turned half a turn).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import trimesh

from calib_core.scene import SceneItem
from calib_core.vision.target_detection import DetectorSettings, TargetDetection
from calib_core.vision.target_spec import BoardSpecError, dictionary, grid, length_mm, spec_error, usage_error

DEFAULT_SPEC = "charuco:9x7:30:22:DICT_5X5_100"
__all__ = ["BoardSpec", "BoardSpecError", "DEFAULT_SPEC", "board_item", "parse_board"]


@dataclass(frozen=True)
class BoardSpec:
    """A ChArUco board: ``squares_x`` by ``squares_y`` squares of ``square_mm``, markers of
    ``marker_mm`` from the ArUco ``dictionary``. Text form: ``charuco:9x7:30:22:DICT_5X5_100``;
    ``legacy`` (text ``...:legacy``) is the layout of OpenCV before 4.6, where a board with an even
    number of rows starts with a white square at the bottom left (ROS-Industrial's boards, OpenCV's
    older samples)."""

    squares_x: int = 9
    squares_y: int = 7
    square_mm: float = 30.0
    marker_mm: float = 22.0
    dictionary: str = "DICT_5X5_100"
    legacy: bool = False

    kind = "charuco"
    unambiguous = True

    @classmethod
    def parse(cls, text: str) -> BoardSpec:
        """A ChArUco text form; any other kind is :func:`parse_board`'s."""
        parts = text.split(":")
        if parts[0] != "charuco" or len(parts) not in (5, 6) or (len(parts) == 6 and parts[5] != "legacy"):
            raise usage_error(text)
        sx, sy = grid(text, parts[1], 3, "squares")
        square = length_mm(text, parts[2], "square")
        marker = length_mm(text, parts[3], "marker")
        if marker >= square:
            raise spec_error(text, f"the marker ({marker:g} mm) must be smaller than the square ({square:g} mm)")
        dictionary(text, parts[4], sx * sy // 2)
        return cls(sx, sy, square, marker, parts[4], len(parts) == 6)

    def __str__(self) -> str:
        return f"charuco:{self.squares_x}x{self.squares_y}:{self.square_mm:g}:{self.marker_mm:g}:{self.dictionary}" + (
            ":legacy" if self.legacy else ""
        )

    @property
    def size_mm(self) -> tuple[float, float]:
        return self.squares_x * self.square_mm, self.squares_y * self.square_mm

    def board(self) -> cv2.aruco.CharucoBoard:
        dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        board = cv2.aruco.CharucoBoard((self.squares_x, self.squares_y), self.square_mm, self.marker_mm, dictionary)
        board.setLegacyPattern(self.legacy)
        return board

    def corners_mm(self) -> np.ndarray:
        """The inner chessboard corners (n, 3) in the board frame, mm."""
        return np.asarray(self.board().getChessboardCorners(), dtype=float)

    def image(self, px_per_mm: float = 4.0) -> np.ndarray:
        w, h = self.size_mm
        return self.board().generateImage(
            (int(round(w * px_per_mm)), int(round(h * px_per_mm))), marginSize=0, borderBits=1
        )

    def detector(self, settings: DetectorSettings | None = None):
        """A function grey image -> :class:`TargetDetection` (build once, use for many images)."""
        settings = settings or DetectorSettings()
        charuco = cv2.aruco.CharucoParameters()
        charuco.tryRefineMarkers = settings.refine_markers
        detector = cv2.aruco.CharucoDetector(self.board(), charuco, settings.aruco, cv2.aruco.RefineParameters())

        def detect(grey: np.ndarray) -> TargetDetection:
            corners, ids, marker_corners, _ = detector.detectBoard(grey)
            seen = 0 if marker_corners is None else len(marker_corners)
            if ids is None or len(ids) == 0:
                return TargetDetection(np.zeros((0, 2)), np.zeros(0, dtype=int), seen)
            return TargetDetection(corners.reshape(-1, 2).astype(np.float64), ids.ravel().astype(int), seen)

        return detect


def parse_board(text: str):
    """The target a ``--board`` text names: ``charuco:...`` (:class:`BoardSpec`), ``chessboard:...``,
    ``circles:...`` or ``aruco:...``; :class:`BoardSpecError` says what the forms are."""
    from calib_core.vision.aruco_grid import ArucoGridSpec
    from calib_core.vision.chessboard import ChessboardSpec
    from calib_core.vision.circle_grid import CircleGridSpec

    if not isinstance(text, str):
        raise BoardSpecError(f"board spec {text!r}: expected text")
    kind = text.split(":", 1)[0].strip().lower()
    kinds = {"charuco": BoardSpec, "chessboard": ChessboardSpec, "circles": CircleGridSpec, "aruco": ArucoGridSpec}
    if kind not in kinds:
        raise usage_error(text)
    return kinds[kind].parse(text)


def board_item(spec, board2world: np.ndarray, name: str = "charuco_board") -> SceneItem:
    """The printed target as a textured plate: its printed face at z = 0 of the board frame, facing -z."""
    w, h = spec.size_mm
    vertices = np.array([[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, h, 0.0], [0.0, h, 0.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    tcoords = np.array([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]])  # image rows run down y; t runs up
    return SceneItem(
        name,
        mesh,
        np.asarray(board2world, dtype=float),
        color=(1.0, 1.0, 1.0),
        kind="fixture",
        texture=spec.image(),
        texture_coords=tcoords,
    )
