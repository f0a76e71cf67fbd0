"""Where the object's colours end: the outline found by foreground and background colour statistics.

A gradient search along an outline sample's normal takes the strongest edge it meets; on a printed part (a frame
of lines 10-15 px inside a box's outline) or in front of clutter that can be the print or the table's grain. The
region-based trackers (RBOT, SRT3D and ICG of DLR's 3DObjectTracking) look instead for where the colours stop
being the object's and start being its surroundings': colour histograms of the object (inside its silhouette at
the current pose) and of a band around it give each pixel a probability of belonging to the object, and along each
outline sample's normal the edge is put where a step from "object" to "surroundings" fits those probabilities
best. An edge inside the print has the object's colours on both sides and scores nothing.

Here it serves the edge fit (:func:`calib_core.look.edge_refinement.refine_to_edges`): an outline sample's
measured offset comes from the step fit, a crease's from the gradient search as before.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from calib_core.look.image_evidence import COLOUR_LEVELS as _LEVELS

_INNER_PX = 5
"""The object's colours are taken this far inside its silhouette at the start pose (the pose may be a few pixels
off)."""
_BAND_PX = (6, 30)
"""Its surroundings' colours: a band this far outside the silhouette (px, inner and outer edge)."""
STEP_LENGTH_PX = 8
"""How many pixels on each side of a candidate edge the step fit weighs."""
MIN_CONTRAST = 0.3
"""The least difference in mean object probability across a found step for it to count (0-1)."""


@dataclass(frozen=True)
class RegionModel:
    """The probability (h, w) float32 that a pixel shows the object rather than its surroundings, from colour
    histograms taken at one pose; ``separation``: how well the two histograms tell the object's pixels from its
    surroundings' (the mean probability on the object minus that around it, 0-1)."""

    object_probability: np.ndarray
    separation: float

    @staticmethod
    def from_image(
        image_rgb: np.ndarray, mask: np.ndarray, origin: tuple[int, int], bins: np.ndarray | None = None
    ) -> "RegionModel | None":
        """The model from ``image_rgb`` (h, w, 3) uint8 and the object's silhouette ``mask`` (uint8, 255 inside)
        whose top-left pixel is ``origin`` (u0, v0) in the image; None where there is too little of either region
        (under 50 pixels) to count. ``bins``: the image's colour bins
        (:attr:`~calib_core.look.image_evidence.ImageEvidence.colour_bins`), when the caller has them."""
        h, w = image_rgb.shape[:2]
        if mask.size == 0 or image_rgb.ndim != 3:
            return None
        full = np.zeros((h, w), np.uint8)
        u0, v0 = origin
        rows, cols = min(mask.shape[0], h - v0), min(mask.shape[1], w - u0)
        if rows <= 0 or cols <= 0:
            return None
        full[v0 : v0 + rows, u0 : u0 + cols] = mask[:rows, :cols]
        # Euclidean distances to the silhouette's edge, from inside and from outside: a disc's erosion and dilations
        # by thresholds (a dilation by a 61 px disc took 6 ms a call, the distance transform a fraction of it)
        from_outside = cv2.distanceTransform(
            np.where(full > 0, 0, 255).astype(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE
        )
        from_inside = cv2.distanceTransform(full, cv2.DIST_L2, cv2.DIST_MASK_PRECISE)
        inner = from_inside > _INNER_PX
        band = (from_outside > _BAND_PX[0]) & (from_outside <= _BAND_PX[1])
        if inner.sum() < 50 or band.sum() < 50:
            return None
        bins = _bins(image_rgb) if bins is None else bins
        n = _LEVELS**3
        h_object = np.bincount(bins[inner], minlength=n).astype(np.float64) / inner.sum()
        h_around = np.bincount(bins[band], minlength=n).astype(np.float64) / band.sum()
        # a colour seen in neither region is even odds; a little of each keeps a rare colour from being certain
        eps = 1.0 / n
        posterior = ((h_object + eps) / (h_object + h_around + 2 * eps)).astype(np.float32)
        probability = posterior[bins]
        separation = float(probability[inner].mean() - probability[band].mean())
        return RegionModel(probability, separation)

    def step_edges(
        self, points_px: np.ndarray, outward: np.ndarray, window_px: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For each outline sample (m, 2) px with its unit normal pointing out of the object (m, 2), where along
        the normal within +-``window_px`` a step from object to surroundings fits the object probabilities best
        (the sum of log-probabilities of object on the inner :data:`STEP_LENGTH_PX` pixels and of surroundings
        on the outer ones): the edge points (m, 2), the step's contrast (m,) (the mean object probability inside
        minus outside, 0-1) and which searches stayed inside the image (m,) bool."""
        h, w = self.object_probability.shape
        L = STEP_LENGTH_PX
        W = int(np.ceil(window_px))
        t = np.arange(-W - L, W + L + 1, dtype=float) + 0.5  # pixel centres along the line; edges fall between them
        lines = points_px[:, None, :] + t[None, :, None] * outward[:, None, :]
        inside = ((lines[..., 0] >= 0) & (lines[..., 0] < w - 1) & (lines[..., 1] >= 0) & (lines[..., 1] < h - 1)).all(
            axis=1
        )
        p = cv2.remap(
            self.object_probability,
            lines[..., 0].astype(np.float32),
            lines[..., 1].astype(np.float32),
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_CONSTANT,
            borderValue=0.5,
        )
        p = np.clip(p, 1e-3, 1 - 1e-3)
        a = np.cumsum(np.log(p), axis=1)  # object on the inner side
        b = np.cumsum(np.log(1 - p), axis=1)  # surroundings on the outer side
        a = np.concatenate([np.zeros((len(p), 1)), a], axis=1)
        b = np.concatenate([np.zeros((len(p), 1)), b], axis=1)
        # an edge at offset d (between pixels k-1 and k, k = d + W + L) weighs pixels k-L..k-1 inside, k..k+L-1 outside
        ks = np.arange(L, 2 * W + L + 1)
        score = (a[:, ks] - a[:, ks - L]) + (b[:, ks + L] - b[:, ks])
        best = np.argmax(score, axis=1)
        rows = np.arange(len(p))
        # sub-pixel: a parabola through the best score and its neighbours
        kb = np.clip(best, 1, len(ks) - 2)
        s0, s1, s2 = score[rows, kb - 1], score[rows, kb], score[rows, kb + 1]
        denom = s0 - 2 * s1 + s2
        sub = np.where((denom < 0) & (best == kb), 0.5 * (s0 - s2) / np.where(denom < 0, denom, -1.0), 0.0)
        offset = (ks[best] - W - L) + sub
        k = ks[best]
        cum_p = np.concatenate([np.zeros((len(p), 1)), np.cumsum(p, axis=1)], axis=1)
        contrast = (cum_p[rows, k] - cum_p[rows, k - L]) / L - (cum_p[rows, k + L] - cum_p[rows, k]) / L
        return points_px + offset[:, None] * outward, contrast, inside


def _bins(image_rgb: np.ndarray) -> np.ndarray:
    from calib_core.look.image_evidence import ImageEvidence

    return ImageEvidence(image_rgb).colour_bins
