"""Which of a look's edge fits is kept: the fits from its starts, in turn, until one settles with most of its samples
on the image's edges; the fit with the most samples on their edges, run again from where it got to. With a prior (a look
on a photograph) a fit that walked beyond three times the prior's reach is no answer however many samples it holds."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import trimesh

from calib_core.camera.intrinsics import Intrinsics
from calib_core.look.coarse_to_fine import coarse_fit, fit_starts
from calib_core.look.edge_refinement import EdgeFit, refine_to_edges
from calib_core.look.image_evidence import ImageEvidence
from calib_core.look.pose_prior import PosePrior
from calib_core.look.target_detectors import TargetDetectors

# a fit settles (is proposed from) with this share of its samples on their edges: wrong minima seen held 52-56 %, the
# least right one 65 % (the bench)
FIT_SHARE = 0.6
CLEAR_SHARE = 0.75  # a settled fit with this share ends the search (the right pose of the demo's frame 12 held 90 %)


@dataclass(frozen=True)
class EdgeFitting:
    """What every edge fit of one look shares: the image's evidence, the camera, the target's mesh, its detectors
    (with a model's view, ``has_view``, theirs leaves out edges without contrast), the settle bound, the colours (the
    outline by colour) and the prior."""

    evidence: ImageEvidence
    intrinsics: Intrinsics
    mesh: trimesh.Trimesh
    detectors: TargetDetectors
    has_view: bool
    rms_bound_px: float
    colour: np.ndarray | None
    prior: PosePrior | None
    colour_bins: np.ndarray | None

    def refine(
        self, start: np.ndarray, *, search_px: float | None = None, shown_at: np.ndarray | None = None
    ) -> EdgeFit:
        """The edges refined from ``start`` (4, 4), leaving out those without contrast in the model's view at
        ``shown_at`` (default ``start``); settled only on more than :data:`FIT_SHARE` of its samples (proposals
        follow from it)."""
        shown = start if shown_at is None else shown_at
        fit = refine_to_edges(
            self.evidence.grey,
            self.intrinsics,
            self.mesh,
            start,
            expected_magnitude=self.detectors.expected_magnitude(shown) if self.has_view else None,
            magnitude=self.detectors.magnitude,
            rms_bound_px=self.rms_bound_px,
            colour=self.colour,
            prior=self.prior,
            colour_bins=self.colour_bins,
            **({} if search_px is None else {"search_px": search_px}),
        )
        return replace(fit, min_share=FIT_SHARE)


def best_settled_fit(
    fitting: EdgeFitting, obj2cam_model: np.ndarray, ranked: Callable[[], list[np.ndarray]], has_prior: bool
) -> EdgeFit:
    """Poses within the robot's error, ranked by their edges' chamfer distance (close up a robot's error moves near
    and far edges differently: no 2D shift lays them all on the image); from the best few, in turn until one settles
    with most of its samples on their edges, the edges pull the pose into place. The fit with the most samples on
    their edges runs again from where it got to, with the model's view and the samples taken afresh there (from a
    turned start a pin seen end-on can lock its rims onto each other: 16 mrad of tilt at 0.37 px, which the second
    pass leaves for the right pose at 0.13 px)."""

    def held(fit: EdgeFit) -> bool:
        # the starts cover the prior's reach: a fit that walked beyond three times it found something else (on LM-O
        # from 10 mm / 3 deg off, fits that slid 35-90 mm along the line of sight onto a neighbour's edges won over
        # starts that settled on the object, and the look said "not found")
        return fitting.prior is None or fitting.prior.holds(fit.obj2cam)

    def rank(fit: EdgeFit) -> tuple[bool, float]:
        settled, count = fit_rank(fit)
        return settled and held(fit), count

    best = None
    for start_pose, coarse in fit_starts(obj2cam_model, ranked, has_prior):
        if coarse:
            start_pose = coarse_fit(
                fitting.evidence, fitting.intrinsics, fitting.mesh, start_pose, fitting.colour, fitting.prior
            )
        fit = fitting.refine(start_pose)
        if best is None or rank(fit) > rank(best):
            best = fit
        if best.settled and held(best) and best.inlier_share >= CLEAR_SHARE:
            break
    again = fitting.refine(best.obj2cam)  # the second pass, for the best start only
    return again if (again.settled and held(again)) or rank(again) > rank(best) else best


def fit_rank(fit: EdgeFit) -> tuple[bool, float]:
    """Settled first, then the most samples on their edges."""
    return fit.settled, fit.inlier_share * fit.samples
