"""The text form of a calibration target (``--board``) and the checks every kind shares.

``kind:COLSxROWS:LENGTH_MM[:...]``: the kinds are in :func:`calib_core.vision.board.parse_board`.
"""

from __future__ import annotations

import math

import cv2

from calib_core.errors import VideocalError

MAX_GRID = 100
FORMS = (
    "charuco:<columns>x<rows>:<square mm>:<marker mm>:<ArUco dictionary>[:legacy] (squares)",
    "chessboard:<columns>x<rows>:<square mm> (inner corners)",
    "circles:<columns>x<rows>:<spacing mm>[:asymmetric]",
    "aruco:<columns>x<rows>:<marker mm>:<gap mm>:<ArUco dictionary> (markers)",
)


class BoardSpecError(VideocalError, ValueError):
    """A board specification (``--board``, a hand-eye board) that does not describe a usable board."""


def spec_error(text: str, why: str) -> BoardSpecError:
    return BoardSpecError(f"board spec {text!r}: {why}")


def usage_error(text: str) -> BoardSpecError:
    return spec_error(text, "expected " + "; or ".join(FORMS))


def grid(text: str, part: str, minimum: int, what: str) -> tuple[int, int]:
    """``COLSxROWS`` as two ints, each from ``minimum`` to :data:`MAX_GRID`."""
    try:
        cols, rows = (int(v) for v in part.lower().split("x"))
    except ValueError:
        raise usage_error(text) from None
    if cols < minimum or rows < minimum:
        raise spec_error(text, f"at least {minimum} x {minimum} {what}")
    if cols > MAX_GRID or rows > MAX_GRID:
        raise spec_error(text, f"at most {MAX_GRID} x {MAX_GRID} {what}")
    return cols, rows


def length_mm(text: str, part: str, what: str, low: float = 0.0) -> float:
    try:
        value = float(part)
    except ValueError:
        raise usage_error(text) from None
    if not (math.isfinite(value) and low < value <= 1000):
        raise spec_error(text, f"the {what} must be more than {low:g} and at most 1000 mm, got {part}")
    return value


def dictionary(text: str, name: str, markers: int) -> None:
    """Check that ``name`` is an OpenCV ArUco dictionary with at least ``markers`` markers."""
    if not name.startswith("DICT_") or not hasattr(cv2.aruco, name):
        raise spec_error(text, f"unknown ArUco dictionary {name!r}")
    available = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, name)).bytesList.shape[0]
    if markers > available:
        raise spec_error(text, f"the board has {markers} markers, {name} only {available}")


def turn_ambiguity(spec, purpose: str) -> str:
    """Why ``spec`` (a target that looks the same turned) cannot serve ``purpose``, and which boards can."""
    what = f"a {spec.kind} target"
    if spec.kind == "chessboard":
        what = (
            f"a chessboard of {spec.cols + 1} x {spec.rows + 1} squares ({spec.cols} x {spec.rows} inner corners, both "
            f"{'odd' if spec.cols % 2 else 'even'})"
        )
    return (
        f"{what} looks the same turned half a turn, so a view does not say which corner is the first: {purpose} needs "
        "a chessboard of odd by even squares (inner corners odd by even, as 9 x 6), or a ChArUco or ArUco board"
    )
