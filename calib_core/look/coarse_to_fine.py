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
    then coarse to fine, and the ranked ones coarse to fine too. On real photographs the chamfer ranking puts clutter
    first (LM-O from 10 mm / 3 deg off: 11 of 24 views within 5 px from the ranked starts, 18 from the prior alone),
    and from 30 mm / 10 deg off the fine fit's 8 px window misses edges 20-35 px away that the half-size fit reaches:
    a ranked start's fine fit alone settled on a white drill beside LM-O's white glue bottle, 28 px off, where from
    the same starts coarse to fine one reached the bottle and the look said `uncertain` (60 views from 30 mm / 10 deg:
    wrong `ok` 1 -> 0, within 5 px 14 -> 16, a view 0.1-0.4 s longer)."""
    if believed:
        yield model, False
        yield model, True
    for start in ranked():
        yield start, believed


COARSEST_WIDTH_PX = 320
"""The coarse fit halves the image while it stays at least this wide, and fits from the smallest up: a 640 x 480 photo
once (320 px), a 1920 x 1440 one twice (480, then 960 px), so that a prior's error reaches about as far in the image
at the coarsest level whatever the camera's resolution."""


def pyramid(evidence: ImageEvidence, intrinsics: Intrinsics) -> list[tuple[ImageEvidence, Intrinsics]]:
    """The image halved while at least :data:`COARSEST_WIDTH_PX` wide (at least once), each level with its camera,
    smallest first: a 640 x 480 photo's is one level of 320 px, a 1920 x 1440 one's two (480 and 960 px)."""
    levels = []
    level, camera = evidence, intrinsics
    while level.shape[1] // 2 >= COARSEST_WIDTH_PX or not levels:
        level, camera = level.half_with(camera)
        levels.append((level, camera))
    return levels[::-1]


def coarse_fit(
    evidence: ImageEvidence, intrinsics: Intrinsics, mesh, start: np.ndarray, colour, prior: PosePrior | None
) -> np.ndarray:
    """``start`` (4, 4) moved by edge fits on the :func:`pyramid`'s levels, smallest first (each halving doubles the
    reach in the image and blurs the clutter's fine edges away): where the full-size fit starts from. On HANDAL's
    1920 x 1440 photos from 30 mm / 10 deg off, two levels gave 3 of 10 `ok` (two within 5 px at 640 px width, one
    9.7 px off) and 1 `uncertain`; the half-size one alone 1 `ok` and 3 `uncertain`."""
    pose = start
    for level, camera in pyramid(evidence, intrinsics):
        pose = refine_to_edges(
            level.grey,
            camera,
            mesh,
            pose,
            magnitude=level.magnitude,
            colour=level.colour if colour is not None else None,
            colour_bins=level.colour_bins if colour is not None else None,
            prior=prior,
        ).obj2cam
    return pose
