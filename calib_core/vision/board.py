"""ChArUco boards: their specification, their image, and a board as a scene item for the test bed."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
import trimesh

from calib_core.errors import VideocalError
from calib_core.scene import SceneItem

DEFAULT_SPEC = "charuco:9x7:30:22:DICT_5X5_100"
MAX_SQUARES = 100


class BoardSpecError(VideocalError, ValueError):
    """A board specification (``--board``, a hand-eye board) that does not describe a usable board."""


@dataclass(frozen=True)
class BoardSpec:
    """A ChArUco board: ``squares_x`` by ``squares_y`` squares of ``square_mm``, markers of
    ``marker_mm`` from the ArUco ``dictionary``. Text form: ``charuco:9x7:30:22:DICT_5X5_100``."""

    squares_x: int = 9
    squares_y: int = 7
    square_mm: float = 30.0
    marker_mm: float = 22.0
    dictionary: str = "DICT_5X5_100"

    @classmethod
    def parse(cls, text: str) -> BoardSpec:
        parts = text.split(":")
        try:
            if len(parts) != 5 or parts[0] != "charuco":
                raise ValueError
            sx, sy = (int(v) for v in parts[1].lower().split("x"))
            spec = cls(sx, sy, float(parts[2]), float(parts[3]), parts[4])
        except ValueError:
            raise BoardSpecError(f"board spec {text!r}: expected charuco:<columns>x<rows>:<square mm>:<marker mm>:<ArUco dictionary>, e.g. {DEFAULT_SPEC}") from None
        if spec.squares_x < 3 or spec.squares_y < 3:
            raise BoardSpecError(f"board spec {text!r}: at least 3 x 3 squares")
        if spec.squares_x > MAX_SQUARES or spec.squares_y > MAX_SQUARES:
            raise BoardSpecError(f"board spec {text!r}: at most {MAX_SQUARES} x {MAX_SQUARES} squares")
        if not (math.isfinite(spec.square_mm) and 0 < spec.square_mm <= 1000):
            raise BoardSpecError(f"board spec {text!r}: the square must be more than 0 and at most 1000 mm")
        if not 0 < spec.marker_mm < spec.square_mm:
            raise BoardSpecError(f"board spec {text!r}: the marker ({spec.marker_mm} mm) must be smaller than the square ({spec.square_mm} mm)")
        if not spec.dictionary.startswith("DICT_") or not hasattr(cv2.aruco, spec.dictionary):
            raise BoardSpecError(f"board spec {text!r}: unknown ArUco dictionary {spec.dictionary!r}")
        markers = spec.squares_x * spec.squares_y // 2
        available = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, spec.dictionary)).bytesList.shape[0]
        if markers > available:
            raise BoardSpecError(f"board spec {text!r}: a {spec.squares_x} x {spec.squares_y} ChArUco board has {markers} markers, {spec.dictionary} only {available}")
        return spec

    def __str__(self) -> str:
        return f"charuco:{self.squares_x}x{self.squares_y}:{self.square_mm:g}:{self.marker_mm:g}:{self.dictionary}"

    @property
    def size_mm(self) -> tuple[float, float]:
        return self.squares_x * self.square_mm, self.squares_y * self.square_mm

    def board(self) -> cv2.aruco.CharucoBoard:
        dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        return cv2.aruco.CharucoBoard((self.squares_x, self.squares_y), self.square_mm, self.marker_mm, dictionary)

    def corners_mm(self) -> np.ndarray:
        """The inner chessboard corners (n, 3) in the board frame (x right, y down the printed image, z into it), mm."""
        return np.asarray(self.board().getChessboardCorners(), dtype=float)

    def image(self, px_per_mm: float = 4.0) -> np.ndarray:
        w, h = self.size_mm
        return self.board().generateImage((int(round(w * px_per_mm)), int(round(h * px_per_mm))), marginSize=0, borderBits=1)


def board_item(spec: BoardSpec, board2world: np.ndarray, name: str = "charuco_board") -> SceneItem:
    """The printed board as a textured plate: its printed face at z = 0 of the board frame, facing -z."""
    w, h = spec.size_mm
    vertices = np.array([[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, h, 0.0], [0.0, h, 0.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    tcoords = np.array([[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]])  # image rows run down y; t runs up
    return SceneItem(name, mesh, np.asarray(board2world, dtype=float), color=(1.0, 1.0, 1.0), kind="fixture", texture=spec.image(), texture_coords=tcoords)
