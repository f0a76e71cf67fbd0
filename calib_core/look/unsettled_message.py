"""Why a look proposes nothing: the target is not where the model puts it (few of its edges meet the image's), its
fit lines up but holds too few of its samples on edges (part of it hidden, or a fit on clutter: the share cannot tell
which, decision 160), or its edges did not settle (with the part's own form error when that is what keeps them off).
The words Find points gives the window and ``locate`` the command line."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.look.edge_alignment import edge_samples_px, matched_share
from calib_core.look.edge_refinement import COARSE_FIT_SHARE, EdgeFit
from calib_core.look.form_tolerance import form_error_px
from calib_core.scene import SceneItem

_MATCHED_SHARE = (
    0.12  # fewer of the target's edge samples on an image edge: it is not there (the edge fit decides the rest)
)


def lines_up(edge_fit: EdgeFit) -> bool:
    """Whether an unsettled fit converged within its RMS bound: too few of its samples found an edge, not too far."""
    return edge_fit.converged and edge_fit.rms_px <= edge_fit.rms_bound_px


def unsettled_message(item: SceneItem, edge_fit: EdgeFit, distance: np.ndarray, intrinsics: Intrinsics) -> str:
    """Why nothing is proposed: the target is not where the model puts it, or its edges did not settle."""
    share = matched_share(edge_samples_px(item.mesh, edge_fit.obj2cam, intrinsics), distance)
    if share < _MATCHED_SHARE:
        return (
            f"{item.name} was not found near where the model puts it (only {100 * share:.0f} % of its edges meet an "
            "edge of the image): pick the points by hand"
        )
    said = (
        f"{item.name}: its edges did not settle on the image (RMS {edge_fit.rms_px:.2f} px, "
        f"{100 * edge_fit.inlier_share:.0f} % of {edge_fit.samples} edge samples on their edges)"
    )
    if lines_up(edge_fit):
        # it lines up: too few of its samples found an edge (a partly hidden object from a robot's error fits so,
        # 2.6-8 px off its truth on LM-O, as does a fit on clutter: which one, the share cannot tell, decision 160)
        least = edge_fit.min_share if edge_fit.rms_px <= 0.5 * edge_fit.px_scale else COARSE_FIT_SHARE
        return said + (
            f": it lines up, but a fit must hold {100 * least:.0f} % of its samples on edges (is part of {item.name} "
            "hidden, in shadow or against a background of its own colour?): pick the points by hand"
        )
    form_px = form_error_px(item, edge_fit.obj2cam, intrinsics)
    if form_px > edge_fit.rms_bound_px and edge_fit.rms_px > edge_fit.rms_bound_px:
        # the part itself keeps its edges off its CAD's by more than a settled fit may be: no look can settle here
        said += (
            f"; its stated form tolerance, {item.form_tolerance_mm:g} mm, is {form_px:.1f} px in this image, above the "
            f"{edge_fit.rms_bound_px:.2f} px a settled fit is held to"
        )
    return said + ": pick the points by hand"
