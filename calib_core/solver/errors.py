"""Bad solver input. Every error names the points involved, numbered from 1 as in the window.

Non-convergence is not an error: it is a ``failed`` status with a reason on the solution.
"""

from __future__ import annotations

from collections.abc import Iterable

from calib_core.errors import VideocalError


def point_label(index: int) -> str:
    """``'point 3'`` for index 2: the window and messages number points from 1."""
    return f"point {index + 1}"


def points_label(indices: Iterable[int]) -> str:
    """``'points 1, 4'`` for indices (0, 3)."""
    idx = [int(i) for i in indices]
    if len(idx) == 1:
        return point_label(idx[0])
    return "points " + ", ".join(str(i + 1) for i in idx)


class SolverInputError(VideocalError, ValueError):
    """Input the pose solver cannot use. ``points`` holds the 0-based indices involved."""

    def __init__(self, message: str, points: Iterable[int] = ()):
        self.points = tuple(int(i) for i in points)
        super().__init__(message)


class TooFewPointsError(SolverInputError):
    """Fewer point pairs than the unknowns need (3, or 4 when focal lengths are estimated)."""


class MismatchedPointsError(SolverInputError):
    """3D and 2D point lists of different lengths or shapes."""


class NonFiniteInputError(SolverInputError):
    """A coordinate is NaN or infinite."""


class DuplicatePointsError(SolverInputError):
    """Two pairs share the same 3D point or the same pixel."""


class DegenerateGeometryError(SolverInputError):
    """The 3D points are collinear (or coincide): no pose can be recovered from them."""


class PointsBehindCameraError(SolverInputError):
    """A given pose (prior or start) puts points at or behind the camera."""


class InvalidIntrinsicsError(SolverInputError):
    """Focal lengths that are not positive and finite."""
