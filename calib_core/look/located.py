"""What a look on a photograph found: the object's pose with its 1-sigma and verdict, the features found and missed
(:func:`calib_core.look.locate.locate`'s result), and its JSON form."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class LocatedFeature:
    """A feature found: ``name``, ``uv_px`` (2,) px in the photo, ``point_mm`` (3,) in the object's frame."""

    name: str
    uv_px: np.ndarray
    point_mm: np.ndarray
    confidence: float
    why: str = ""


@dataclass(frozen=True)
class Located:
    """``status``: ``ok`` (the edges settled: converged, within their RMS bound, at least half the samples on
    their edges, and every other start that settled put the object within a few pixels of it in the image),
    ``uncertain`` (settled, but another start settled elsewhere in the image: the message says how far), else
    ``not found`` with ``message`` saying why. ``obj2cam`` (4, 4) mm: the edge fit's pose
    (``None`` when not found); ``std_rotation_deg`` (3,) and ``std_translation_mm`` (3,): its 1-sigma, about the
    camera's axes; ``features`` found and ``missed`` (name, reason); ``features_obj2cam`` the pose of the features
    alone (four or more, else ``None``) and ``features_vs_edges_mm`` how far its origin is from the edges' (the two
    share no measurement)."""

    status: str
    message: str
    obj2cam: np.ndarray | None
    std_rotation_deg: np.ndarray | None
    std_translation_mm: np.ndarray | None
    edge_rms_px: float | None
    edge_share: float | None
    edge_samples: int
    features: tuple[LocatedFeature, ...] = ()
    missed: tuple[tuple[str, str], ...] = ()
    features_obj2cam: np.ndarray | None = None
    features_vs_edges_mm: float | None = None
    prior_moved_mm: float | None = None
    prior_turned_deg: float | None = None
    seconds: float = 0.0
    extra: dict = field(default_factory=dict)
    covariance: np.ndarray | None = field(default=None, repr=False)
    """(6, 6) of the pose: the rotation vector (rad) and the translation (mm), camera frame, as the edge fit's step
    moves it; widened by the spread of the starts that agree."""
    points_sigma_px: float | None = None
    """How far the object's points may lie from where ``obj2cam`` puts them in the image, 1-sigma px (the largest over
    its vertices): what a pose error scored as BOP scores it (MSPD) would be."""
    rival_obj2cam: np.ndarray | None = field(default=None, repr=False)
    """(4, 4) mm: where the rival that made the answer ``uncertain`` puts the object (the furthest in the image of the
    settled fits that hold about as many of their edges), else ``None``: the other explanation the photo holds, for
    an operator to look at beside the answer."""

    def to_dict(self) -> dict:
        """The JSON form (mm, degrees): ``R_obj2cam``, ``t_obj2cam_mm``, ``std`` and the rest."""

        def matrix(a):
            return None if a is None else np.round(np.asarray(a, float), 9).tolist()

        return {
            "status": self.status,
            "message": self.message,
            "R_obj2cam": matrix(None if self.obj2cam is None else self.obj2cam[:3, :3]),
            "t_obj2cam_mm": matrix(None if self.obj2cam is None else self.obj2cam[:3, 3]),
            "std": None
            if self.std_translation_mm is None
            else {"rotation_deg": matrix(self.std_rotation_deg), "translation_mm": matrix(self.std_translation_mm)},
            "edges": {
                "rms_px": _finite(self.edge_rms_px),
                "share_on_edges": _finite(self.edge_share),
                "samples": self.edge_samples,
            },
            "features": [
                {
                    "name": f.name,
                    "uv_px": matrix(f.uv_px),
                    "point_mm": matrix(f.point_mm),
                    "confidence": round(f.confidence, 3),
                    **({"unsure_because": f.why} if f.why else {}),
                }
                for f in self.features
            ],
            "missed": [{"name": n, "reason": r} for n, r in self.missed],
            "features_pose": None
            if self.features_obj2cam is None
            else {
                "R_obj2cam": matrix(self.features_obj2cam[:3, :3]),
                "t_obj2cam_mm": matrix(self.features_obj2cam[:3, 3]),
                "origin_from_edges_mm": self.features_vs_edges_mm,
            },
            "moved_from_prior": None
            if self.prior_moved_mm is None
            else {"mm": self.prior_moved_mm, "deg": self.prior_turned_deg},
            "rival": None
            if self.rival_obj2cam is None
            else {
                "R_obj2cam": matrix(self.rival_obj2cam[:3, :3]),
                "t_obj2cam_mm": matrix(self.rival_obj2cam[:3, 3]),
                "apart_px": self.extra.get("rival_apart_px"),
            },
            "starts_apart_mm": self.extra.get("starts_apart_mm"),
            "starts_apart_px": self.extra.get("starts_apart_px"),
            "points_sigma_px": _finite(self.points_sigma_px),
            "seconds": round(self.seconds, 3),
        }


def _finite(value: float | None) -> float | None:
    """JSON has no infinity: a fit that found no sample has no RMS."""
    return None if value is None or not np.isfinite(value) else round(float(value), 4)
