"""Where an edge fit on a photograph starts: from the prior itself, at full size and from a fit at half size, then
from the ranked starts; the half-size fit reaches edges twice as far in the image, with the clutter's fine edges
blurred away."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.look.edge_refinement import refine_to_edges
from calib_core.look.image_evidence import ImageEvidence
from calib_core.look.pose_prior import PosePrior


def fit_starts(
    model: np.ndarray, ranked: Callable[[], list[np.ndarray]], believed: bool
) -> Iterator[tuple[np.ndarray, bool]]:
    """The starts of the edge fit in turn, each with whether it goes coarse to fine: the ranked ones (``ranked()``,
    asked for only when the fit gets to them: ranking a reach's thousands of poses is a fifth of a look that settles
    from the prior); with a prior believed (a look on a photograph), first the modelled pose itself, at full size and
    then coarse to fine. On real photographs the chamfer ranking puts clutter first (LM-O from 10 mm / 3 deg off: 11
    of 24 views within 5 px from the ranked starts, 18 from the prior alone), and from 30 mm / 10 deg off the fine
    fit's 8 px window misses edges 20-35 px away that the half-size fit reaches."""
    if believed:
        yield model, False
        yield model, True
    for start in ranked():
        yield start, False


def coarse_fit(
    evidence: ImageEvidence, intrinsics: Intrinsics, mesh, start: np.ndarray, colour, prior: PosePrior | None
) -> np.ndarray:
    """``start`` (4, 4) moved by an edge fit on the image at half size (twice the reach in the image, the clutter's
    fine edges blurred away): where the full-size fit starts from."""
    half = evidence.half()
    fit = refine_to_edges(
        half.grey,
        intrinsics.scaled(0.5),
        mesh,
        start,
        magnitude=half.magnitude,
        colour=half.colour if colour is not None else None,
        colour_bins=half.colour_bins if colour is not None else None,
        prior=prior,
    )
    return fit.obj2cam
