"""What a look reads from one image, computed once: its grey, its gradient, its edges and their distance map, its
colours' histogram bins, and the same at half size (where a coarse-to-fine fit starts).

A look on a photograph fits from several starts (the prior, starts round it, starts nearer and further), Find points
ranks and refines from several more, and a pick in the window reads the same frame again: each used to convert to
grey, take the gradient and run Canny afresh (ten Canny and five gradient passes a photo). An :class:`ImageEvidence`
is made once per image and computes each on first use; every start, Find points and the picks share it.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cached_property

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.look import colour_contrast

COLOUR_LEVELS = 32
"""Levels per channel of the colour histograms' bins (32^3 RGB colours; :mod:`calib_core.look.region_model`)."""


class ImageEvidence:
    """One camera image (h, w) grey or (h, w, 3) RGB, uint8, and what is computed from it, each on first use.

    Pixels are the image's own (u right, v down, px); :meth:`half` is the image at half size, whose pixel (u, v) is
    this image's (2u + 0.5, 2v + 0.5): :meth:`half_with` gives it with its camera.
    The image is not copied and must not change while the evidence is in use.

    Its public members are the image (``source``, ``image``, ``shape``, ``colour``) and what a look reads from it, each
    computed once (grey, the two gradients, the edges and their distance maps, the colour bins, the half with its
    camera): one image's evidence, which every start of a look shares."""

    def __init__(self, image: np.ndarray):
        image = np.asarray(image)
        if image.dtype != np.uint8 or image.ndim not in (2, 3) or (image.ndim == 3 and image.shape[2] < 3):
            raise ValueError(f"an image is (h, w) or (h, w, 3) uint8, not {image.shape} {image.dtype}")
        self.source = image
        """The array given (what a caller compares to tell whether this evidence is of its frame)."""
        self.image = np.ascontiguousarray(image if image.ndim == 2 else image[..., :3])
        self._distances: dict[float, np.ndarray] = {}

    @staticmethod
    def of(image: np.ndarray | ImageEvidence) -> ImageEvidence:
        """``image`` itself when it is evidence already, else its evidence (new)."""
        return image if isinstance(image, ImageEvidence) else ImageEvidence(image)

    @property
    def shape(self) -> tuple[int, ...]:
        return self.image.shape

    @property
    def colour(self) -> np.ndarray | None:
        """The image (h, w, 3) RGB, or ``None`` for a grey image."""
        return self.image if self.image.ndim == 3 else None

    @cached_property
    def grey(self) -> np.ndarray:
        """(h, w) uint8: OpenCV's luma of an RGB image, the image itself when grey."""
        return self.image if self.image.ndim == 2 else cv2.cvtColor(self.image, cv2.COLOR_RGB2GRAY)

    @cached_property
    def magnitude(self) -> np.ndarray:
        """(h, w) float32: the gradient magnitude of lightness and colour
        (:func:`calib_core.look.colour_contrast.gradient_magnitude`), grey levels or Lab steps per pixel."""
        return colour_contrast.gradient_magnitude(self.image)

    @cached_property
    def grey_magnitude(self) -> np.ndarray:
        """(h, w) float32: the gradient magnitude of :attr:`grey` alone, grey levels per pixel (a click's rim search:
        a rim is a step of lightness, and a colour edge beside it would draw the search off)."""
        return self.magnitude if self.colour is None else colour_contrast.gradient_magnitude(self.grey)

    @cached_property
    def edges(self) -> np.ndarray:
        """(h, w) uint8 {0, 255}: Canny's edges of lightness and colour (:func:`colour_contrast.edges`)."""
        return colour_contrast.edges(self.image)

    @cached_property
    def _edge_distance(self) -> np.ndarray:
        return cv2.distanceTransform((self.edges == 0).astype(np.uint8), cv2.DIST_L2, 3)

    def edge_distance(self, truncate_px: float) -> np.ndarray:
        """(h, w) float32 px: every pixel's distance to the nearest of :attr:`edges`, truncated at ``truncate_px``."""
        key = float(truncate_px)
        if key not in self._distances:
            self._distances[key] = np.minimum(self._edge_distance, key).astype(np.float32)
        return self._distances[key]

    @cached_property
    def colour_bins(self) -> np.ndarray | None:
        """(h, w) int32: each pixel's colour histogram bin (:data:`COLOUR_LEVELS` per channel), ``None`` when grey."""
        if self.colour is None:
            return None
        q = (self.image.astype(np.int32) * COLOUR_LEVELS) >> 8
        return (q[..., 0] * COLOUR_LEVELS + q[..., 1]) * COLOUR_LEVELS + q[..., 2]

    def half(self) -> ImageEvidence:
        """The evidence of this image at half size, kept: each pixel the mean of a 2 x 2 block (an odd last row or
        column left out), so that ``intrinsics.scaled(0.5)`` is its camera exactly (a Gaussian pyramid's
        ``pyrDown`` keeps every second pixel instead: its camera is off by a quarter pixel)."""
        if "_half" not in self.__dict__:
            h, w = self.image.shape[:2]
            even = self.image[: h - h % 2, : w - w % 2]
            self.__dict__["_half"] = ImageEvidence(cv2.resize(even, (w // 2, h // 2), interpolation=cv2.INTER_AREA))
        return self.__dict__["_half"]

    def half_with(self, intrinsics: Intrinsics) -> tuple[ImageEvidence, Intrinsics]:
        """:meth:`half` and its camera: ``intrinsics`` (this image's) scaled by a half, its width and height the
        half's own (an odd last row or column is left out, where scaling the size would round it in)."""
        half = self.half()
        camera = intrinsics.scaled(0.5)
        return half, replace(camera, width=half.shape[1], height=half.shape[0])
