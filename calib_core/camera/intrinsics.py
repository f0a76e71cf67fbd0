"""Camera intrinsics: focal lengths, principal point, image size, lens distortion."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

DISTORTION_NAMES = ("k1", "k2", "p1", "p2", "k3")
DISTORTION_MODELS = {
    "plumb_bob": ("k1", "k2", "p1", "p2", "k3"),
    "rational_polynomial": ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
    "equidistant": ("k1", "k2", "k3", "k4"),
}
"""The lens models, by ROS's ``distortion_model`` names, with their coefficients in OpenCV's order: OpenCV's
5-parameter model, its 8-parameter rational model, and its fisheye (equidistant, Kannala-Brandt) model."""


MAX_IMAGE_SIDE_PX = 20000
"""Larger than any camera's sensor; a bigger number is a typo that would allocate gigabytes."""


MAX_DISTORTION = 1e4
"""The largest distortion coefficient taken (in size): a real lens's are under 10 (a rational model's a few hundred);
-1e308 is a damaged file, which would send every projection to infinity."""
MAX_INTRINSIC_PX = 1e6
"""The largest focal length or principal point (px) a camera has: a long lens on a large sensor is 1e4-1e5 px;
1e23 is a unit error, and the projections and renders made from it are nothing."""


@dataclass(frozen=True)
class Intrinsics:
    """A camera: a pinhole with lens distortion.

    ``fu``, ``fv``: focal lengths, px. ``cx``, ``cy``: principal point, px, with the
    centre of the top-left pixel at (0, 0) as in OpenCV. ``width``, ``height``: image
    size, px. ``distortion``: the coefficients of ``model`` (:data:`DISTORTION_MODELS`), dimensionless:
    ``(k1, k2, p1, p2, k3)`` for ``plumb_bob`` (the default), eight for ``rational_polynomial``,
    ``(k1, k2, k3, k4)`` for ``equidistant`` (OpenCV's fisheye model).
    """

    fu: float
    fv: float
    cx: float
    cy: float
    width: int
    height: int
    distortion: tuple[float, ...] = field(default=(0.0, 0.0, 0.0, 0.0, 0.0))
    model: str = "plumb_bob"

    def __post_init__(self) -> None:
        for name in ("fu", "fv", "cx", "cy"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise ValueError(f"intrinsics: {name} must be finite, got {v}")
            if abs(v) > MAX_INTRINSIC_PX:
                raise ValueError(
                    f"intrinsics: {name} = {v:g} px is no camera's (at most {MAX_INTRINSIC_PX:g} px: a unit error?)"
                )
            object.__setattr__(self, name, v)
        if self.fu <= 0 or self.fv <= 0:
            raise ValueError(f"intrinsics: focal lengths must be positive, got fu={self.fu}, fv={self.fv}")
        for name in ("width", "height"):
            v = getattr(self, name)
            if int(v) != v or int(v) <= 0:
                raise ValueError(f"intrinsics: {name} must be a positive whole number of pixels, got {v}")
            if int(v) > MAX_IMAGE_SIDE_PX:
                raise ValueError(
                    f"intrinsics: {name} is {v} pixels; videocal takes images up to {MAX_IMAGE_SIDE_PX} pixels a side"
                )
            object.__setattr__(self, name, int(v))
        if self.model not in DISTORTION_MODELS:
            raise ValueError(
                f"intrinsics: unknown distortion model {self.model!r}; videocal knows {', '.join(DISTORTION_MODELS)}"
            )
        names = DISTORTION_MODELS[self.model]
        d = tuple(float(x) for x in np.asarray(self.distortion, dtype=float).ravel())
        if len(d) != len(names):
            raise ValueError(
                f"intrinsics: {self.model} distortion needs {len(names)} values ({', '.join(names)}), got {len(d)}"
            )
        if not all(np.isfinite(d)):
            raise ValueError("intrinsics: distortion contains NaN or infinite values")
        if max((abs(x) for x in d), default=0.0) > MAX_DISTORTION:
            k = max(range(len(d)), key=lambda i: abs(d[i]))
            raise ValueError(
                f"intrinsics: distortion {names[k]} = {d[k]:g} is no lens's (at most {MAX_DISTORTION:g} in size)"
            )
        object.__setattr__(self, "distortion", d)

    @property
    def K(self) -> np.ndarray:
        """Camera matrix (3, 3), px."""
        return np.array([[self.fu, 0.0, self.cx], [0.0, self.fv, self.cy], [0.0, 0.0, 1.0]])

    @property
    def dist_coeffs(self) -> np.ndarray:
        """Distortion as OpenCV wants it: array (5,), (8,) or, for ``equidistant`` (``cv2.fisheye``), (4,)."""
        return np.asarray(self.distortion, dtype=float)

    @property
    def distortion_names(self) -> tuple[str, ...]:
        return DISTORTION_MODELS[self.model]

    @property
    def has_distortion(self) -> bool:
        return any(d != 0.0 for d in self.distortion)

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)`` in px."""
        return (self.width, self.height)

    def without_distortion(self) -> Intrinsics:
        """The ideal pinhole camera of the same focal lengths and principal point."""
        return replace(self, distortion=(0.0, 0.0, 0.0, 0.0, 0.0), model="plumb_bob")

    def with_focal(self, fu: float, fv: float) -> Intrinsics:
        return replace(self, fu=fu, fv=fv)

    def scaled(self, factor: float) -> Intrinsics:
        """The same camera at another resolution (``factor`` times width and height)."""
        return replace(
            self,
            fu=self.fu * factor,
            fv=self.fv * factor,
            cx=(self.cx + 0.5) * factor - 0.5,
            cy=(self.cy + 0.5) * factor - 0.5,
            width=int(round(self.width * factor)),
            height=int(round(self.height * factor)),
        )

    def contains(self, pixels: np.ndarray, margin_px: float = 0.0) -> np.ndarray:
        """Boolean mask (n,): which pixels (n, 2) lie inside the image, ``margin_px`` in from the edge."""
        p = np.asarray(pixels, dtype=float).reshape(-1, 2)
        lo = -0.5 + margin_px
        return (
            (p[:, 0] >= lo)
            & (p[:, 1] >= lo)
            & (p[:, 0] <= self.width - 0.5 - margin_px)
            & (p[:, 1] <= self.height - 0.5 - margin_px)
        )

    def to_dict(self) -> dict:
        out = {
            "fu": self.fu,
            "fv": self.fv,
            "cx": self.cx,
            "cy": self.cy,
            "width": self.width,
            "height": self.height,
            "distortion": list(self.distortion),
        }
        if self.model != "plumb_bob":  # files of the default model stay as older videocal wrote them
            out["distortion_model"] = self.model
        return out

    @classmethod
    def from_dict(cls, data: dict) -> Intrinsics:
        """From ``{"fu", "fv", "cx", "cy", "width", "height", optional "distortion"}``.

        Raises ``ValueError`` naming the missing or bad field.
        """
        if not isinstance(data, dict):
            raise ValueError("intrinsics: expected an object with fu, fv, cx, cy, width, height")
        missing = [k for k in ("fu", "fv", "cx", "cy", "width", "height") if k not in data]
        if missing:
            raise ValueError(f"intrinsics: missing field(s) {', '.join(missing)}")
        unknown = set(data) - {"fu", "fv", "cx", "cy", "width", "height", "distortion", "distortion_model"}
        if unknown:
            raise ValueError(f"intrinsics: unknown field(s) {', '.join(sorted(unknown))}")
        kwargs = {}
        for k in ("fu", "fv", "cx", "cy", "width", "height"):
            v = data[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"intrinsics: field '{k}' must be a number, got {v!r}")
            kwargs[k] = v
        if "distortion" in data:
            kwargs["distortion"] = tuple(data["distortion"])
        if "distortion_model" in data:
            kwargs["model"] = str(data["distortion_model"])
        return cls(**kwargs)
