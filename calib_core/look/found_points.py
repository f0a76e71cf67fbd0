"""What Find points answers: the features found (proposals, each with its pixel, its point and how sure the
detector was), the ones not found with the reason, and the edge fit the detections were checked against."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from calib_core.look.edge_refinement import EdgeFit


@dataclass(frozen=True)
class Proposal:
    """A feature found: ``uv_px`` (2,) px, ``point_mm`` (3,) in the component's frame, ``confidence``
    in [0, 1] (the detector's, times 1 when the final pose fit keeps it), ``residual_px`` its distance
    from the final pose's projection."""

    feature: str
    kind: str
    uv_px: np.ndarray
    point_mm: np.ndarray
    confidence: float
    residual_px: float
    why: str = ""
    """What made the detector unsure, when its confidence is below one half (empty otherwise)."""


@dataclass(frozen=True)
class Missed:
    feature: str
    reason: str


@dataclass(frozen=True)
class FoundPoints:
    """``found``: the target was located and at least four features proposed; ``message`` says what
    happened in a sentence; ``offset_px`` (2,) the shift between model and image; ``obj2cam`` (4, 4)
    the robust fit's pose (``None`` when not found); ``seconds`` the time taken."""

    component: str
    found: bool
    message: str
    proposals: tuple[Proposal, ...] = ()
    missed: tuple[Missed, ...] = ()
    offset_px: np.ndarray = field(default_factory=lambda: np.zeros(2))
    obj2cam: np.ndarray | None = None
    seconds: float = 0.0
    edges: EdgeFit | None = None
    """The edge refinement's result (the pose the detections were checked against), when it ran."""
    edge_seconds: float = 0.0
    """The time the edges took: the search for where to start, the refinement, its second pass and its
    check from the features' pose (s)."""
