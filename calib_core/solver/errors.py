"""Bad solver input. Every error names the points involved, numbered from 1 as in the window.

Non-convergence is not an error: it is a ``failed`` status with a reason on the solution.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterable, Iterator, Sequence

import numpy as np

from calib_core.errors import VideocalError

_NAMES: contextvars.ContextVar[tuple[str, tuple[int, ...]] | None] = contextvars.ContextVar("point_names", default=None)


@contextlib.contextmanager
def named_points(word: str, numbers: Sequence[int]) -> Iterator[None]:
    """Within this block, messages name point ``i`` as ``f"{word} {numbers[i]}"``: the window's solves
    say ``pair 12`` for the pair the table shows as 12, whatever its place in the solve."""
    token = _NAMES.set((word, tuple(np.asarray(numbers, dtype=np.int64).reshape(-1).tolist())))
    try:
        yield
    finally:
        _NAMES.reset(token)


@contextlib.contextmanager
def named_points_as_given(rows: Sequence[int]) -> Iterator[None]:
    """Within this block point ``i`` of a solve on a subset is named as the pair ``rows[i]`` it came
    from (in the caller's names, when there are any)."""
    outer = _NAMES.get()
    word = outer[0] if outer is not None else "point"
    rows = np.asarray(rows, dtype=np.int64).reshape(-1)
    numbers = rows + 1
    if outer is not None and len(outer[1]):
        known = np.asarray(outer[1], dtype=np.int64)
        inside = rows < len(known)
        numbers[inside] = known[rows[inside]]
    with named_points(word, numbers):
        yield


LISTED = 12
"""The most points a message names one by one."""


def _number(index: int) -> tuple[str, str]:
    names = _NAMES.get()
    if names is not None and 0 <= index < len(names[1]):
        return names[0], str(names[1][index])
    return "point", str(index + 1)


def point_label(index: int) -> str:
    """``'point 3'`` for index 2 (numbered from 1), or the caller's name for it (:func:`named_points`)."""
    word, number = _number(int(index))
    return f"{word} {number}"


def points_label(indices: Iterable[int]) -> str:
    """``'points 1, 4'`` for indices (0, 3) (or ``'pairs 9, 12'`` inside :func:`named_points`); beyond
    :data:`LISTED` of them the first ones and how many more (``'points 1, 2, ..., 10 and 1490 more'``): a message
    that names every one of a detector's thousand rejected pairs is read by no one."""
    idx = indices if isinstance(indices, (np.ndarray, list, tuple)) else list(indices)
    if len(idx) == 1:
        return point_label(int(idx[0]))
    labels = [_number(int(i)) for i in idx[:LISTED]]  # (only those named are converted: a robust solve drops thousands)
    more = f" and {len(idx) - LISTED} more" if len(idx) > LISTED else ""
    return f"{labels[0][0]}s " + ", ".join(n for _, n in labels) + more


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


class OutOfRangeInputError(SolverInputError):
    """A coordinate far beyond any cell or sensor (a unit mistake, or a number no one meant)."""


class DuplicatePointsError(SolverInputError):
    """Two pairs share the same 3D point or the same pixel."""


class RepeatedPairError(DuplicatePointsError):
    """One pair given twice (the same 3D point at the same pixel); ``solve_pose`` counts it once. ``same_pixel``: the
    index pairs (i < j) found at one pixel, so that the pairs given again are told without a second search."""

    def __init__(self, message: str, points: Iterable[int] = (), same_pixel: Sequence[tuple[int, int]] = ()):
        super().__init__(message, points)
        self.same_pixel = tuple(same_pixel)


class DegenerateGeometryError(SolverInputError):
    """The 3D points are collinear (or coincide): no pose can be recovered from them."""


class PointsBehindCameraError(SolverInputError):
    """A given pose (prior or start) puts points at or behind the camera."""


class InvalidIntrinsicsError(SolverInputError):
    """Focal lengths that are not positive and finite."""
