"""Find points on the image halved, for a part whose form error is more pixels than the edge fit can average over.

The edge fit's search along each sample's normal narrows to :data:`~calib_core.look.edge_refinement.FINEST_WINDOW_PX`
either side. A part made to a form tolerance (a printed fixture up to a millimetre off its CAD) has edges that bend
off the CAD's by that much: close up, 3.3 px of bend at the workshop camera's full size, and the samples near the
bend's crest fall out of the narrowed window, so the fit follows the rest of the outline and tilts to it (2.2 deg on
the fixture, its features then 3-22 px from their detections). In the image halved the same bend is 1.6 px, inside
the window: every sample stays and the fit averages the bend out, as the workshop camera's half-size looks did. So a
part whose stated tolerance is more pixels than that is looked at on the image halved (the evidence's own half: each
pixel the mean of a 2 x 2 block, whose camera is exactly ``intrinsics.scaled(0.5)``; halved again while the bend is
still more and the image wide enough), and the answer is given back in the full image's pixels. On the workshop camera
at full size the demo then corrects its 8.1 mm to 0.26-0.36 mm, as at half size (0.21-0.42 mm).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from calib_core.look.edge_refinement import FINEST_WINDOW_PX, EdgeFit
from calib_core.look.found_points import FoundPoints
from calib_core.look.image_evidence import ImageEvidence

SMALLEST_HALVED_WIDTH_PX = 320
"""An image is not halved below this width: the features' detectors need a few pixels of each edge."""


def halvings(form_px: float, width_px: int) -> int:
    """How many times to halve an image ``width_px`` wide for a part whose stated form tolerance is ``form_px`` in it:
    until the bend is within the fit's finest window, while the image stays :data:`SMALLEST_HALVED_WIDTH_PX` wide
    (0: looked at as it is)."""
    count = 0
    while form_px / 2**count > FINEST_WINDOW_PX and width_px // 2 ** (count + 1) >= SMALLEST_HALVED_WIDTH_PX:
        count += 1
    return count


def size_said(count: int) -> str:
    """The size of an image halved ``count`` times, in words."""
    return {1: "half its size", 2: "a quarter of its size"}.get(count, f"1/{2**count} of its size")


def halved_view(expected, count: int = 1):
    """``expected(obj2cam, box_px=, supersample=) -> (h, w, 3)`` (the model's view at full size, only ``box_px``
    rendered) for the image halved ``count`` times: the box's full-size pixels rendered and halved as
    :meth:`~calib_core.look.image_evidence.ImageEvidence.half` halves the photo (each 2 x 2 block averaged)."""
    if expected is None:
        return None
    scale = 2**count

    def view(obj2cam: np.ndarray, box_px=None, supersample: float = 1):
        full_box = None if box_px is None else tuple(scale * int(b) for b in box_px)
        view = ImageEvidence(expected(obj2cam, box_px=full_box, supersample=supersample))
        for _ in range(count):
            view = view.half()
        return view.image

    return view


def _to_full(uv_px: np.ndarray, scale: float) -> np.ndarray:
    """Pixels (..., 2) of the image made ``scale`` times smaller in the full one (pixel centres at whole numbers in
    both, as :meth:`~calib_core.camera.intrinsics.Intrinsics.scaled` has them)."""
    return (np.asarray(uv_px, dtype=float) + 0.5) * scale - 0.5


def _edges_at_full_size(fit: EdgeFit, scale: float) -> EdgeFit:
    return replace(
        fit,
        rms_px=scale * fit.rms_px,
        sigma_px=scale * fit.sigma_px,
        edges_px=_to_full(fit.edges_px, scale) if len(fit.edges_px) else fit.edges_px,
        offsets_px=scale * fit.offsets_px,
        residuals_px=scale * fit.residuals_px,
        rms_bound_px=scale * fit.rms_bound_px,
        px_scale=scale * fit.px_scale,
    )


def at_full_size(found: FoundPoints, count: int, why: str) -> FoundPoints:
    """``found`` on the image halved ``count`` times, in the full image's pixels; its message, whose figures are the
    halved image's, says so and ``why`` it was halved."""
    scale = float(2**count)
    return replace(
        found,
        message=f"{found.message} (looked at the image at {size_said(count)}, where the figures above are measured: "
        f"{why})",
        proposals=tuple(
            replace(p, uv_px=_to_full(p.uv_px, scale), residual_px=scale * p.residual_px) for p in found.proposals
        ),
        offset_px=scale * np.asarray(found.offset_px, dtype=float),
        edges=None if found.edges is None else _edges_at_full_size(found.edges, scale),
    )
