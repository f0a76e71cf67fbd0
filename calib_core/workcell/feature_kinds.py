"""What kind of image feature a named feature point is, so Find points can pick its detector.

In the workcell file a feature is either the plain ``name: [x, y, z]`` (a corner) or a mapping::

    boss_top_left: {at: [4, -55, 40], kind: circle, radius_mm: 10, normal: [1, 0, 0]}
    marker_dot: {at: [0, 12, 30], kind: point}

- ``corner``: where two edges meet (``cv2.cornerSubPix`` after a corner detector);
- ``circle``: the centre of a round edge of ``radius_mm`` in the plane of ``normal`` (item frame): the
  centre of the fitted ellipse, corrected for perspective (the ellipse's centre is not the image of the
  circle's centre);
- ``point``: a small blob darker or brighter than around it (its centroid).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KINDS = ("corner", "circle", "point")


@dataclass(frozen=True)
class FeatureKind:
    """``kind`` one of :data:`KINDS`; for a circle ``radius_mm`` and the unit ``normal`` (3,) in the item frame."""

    kind: str = "corner"
    radius_mm: float | None = None
    normal: tuple[float, float, float] | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"feature kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.kind == "circle":
            if self.radius_mm is None or not (np.isfinite(self.radius_mm) and 0 < self.radius_mm <= 10_000):
                raise ValueError(f"a circle needs radius_mm in (0, 10000] mm, got {self.radius_mm}")
            n = np.asarray(self.normal if self.normal is not None else (np.nan,) * 3, dtype=float)
            if n.shape != (3,) or not np.all(np.isfinite(n)) or np.linalg.norm(n) < 1e-9:
                raise ValueError(f"a circle needs a normal: three numbers, not all zero, got {self.normal}")
            object.__setattr__(self, "normal", tuple(float(v) for v in n / np.linalg.norm(n)))

    def to_yaml(self, point_mm) -> list | dict:
        """The workcell file's form of a feature at ``point_mm`` (3,) of this kind."""
        at = [float(v) for v in point_mm]
        if self.kind == "corner":
            return at
        entry = {"at": at, "kind": self.kind}
        if self.kind == "circle":
            entry["radius_mm"] = float(self.radius_mm)
            entry["normal"] = list(self.normal)
        return entry


CORNER = FeatureKind()
