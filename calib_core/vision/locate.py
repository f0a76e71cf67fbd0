"""A look on any photograph: a known object's pose in a camera's frame from one image, its edges and features.

What the window does at a task location (Find points and the edge fit, :mod:`calib_core.vision.find_points`),
on a photo of one object with nothing else known: the object's mesh, the camera's intrinsics and a rough pose
(the prior) to start from. So a look can be checked on real photographs (a phone photo of a box and its mesh),
not only on the simulated camera.

The pose reported is the edge fit's: hundreds of samples along the object's outline and creases, with its
covariance (each edge chain's samples taken as one measurement). The features found are reported with their
pixels and, when four or more agree, the pose they give on their own: two measurements that share no sample.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import check_transform, rotation_angle_deg
from calib_core.scene import SceneItem
from calib_core.solver import solve_pose
from calib_core.vision.find_points import REACH_DEG, REACH_MM, FoundPoints, find_points

PHOTO_EDGE_RMS_PX = 1.5
"""The edge fit's settle bound on a photograph, px (with three quarters of the samples on their edges): a
photographed cardboard box fits its outline to 1.1-1.4 px (rounded edges, JPEG, an uncalibrated lens), where the
cell's camera is held to 0.5 px."""
MAX_DEFAULT_FEATURES = 64
"""A mesh of at most this many vertices (a box, a plate) gives its vertices as corner features by default."""


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
            "starts_apart_mm": self.extra.get("starts_apart_mm"),
            "starts_apart_px": self.extra.get("starts_apart_px"),
            "seconds": round(self.seconds, 3),
        }


def _finite(value: float | None) -> float | None:
    """JSON has no infinity: a fit that found no sample has no RMS."""
    return None if value is None or not np.isfinite(value) else round(float(value), 4)


def default_features(mesh) -> dict[str, np.ndarray]:
    """The mesh's vertices (mm) named ``v0``, ``v1``, ... as corners when it has at most
    :data:`MAX_DEFAULT_FEATURES` (a box's eight), else none: a finely meshed object's vertices are not corners."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    if len(vertices) > MAX_DEFAULT_FEATURES:
        return {}
    return {f"v{i}": v.copy() for i, v in enumerate(vertices)}


def locate(
    image: np.ndarray,
    intrinsics: Intrinsics,
    mesh,
    prior_obj2cam: np.ndarray,
    *,
    features: dict[str, np.ndarray] | None = None,
    expected=None,
    reach_mm: float = REACH_MM,
    reach_deg: float = REACH_DEG,
    name: str = "object",
    color=(0.7, 0.7, 0.7),
) -> Located:
    """The pose of the object ``mesh`` (mm, its own frame) in ``image`` (h, w[, 3]) uint8 taken by a camera of
    ``intrinsics``, starting from ``prior_obj2cam`` (4, 4, mm: the object's frame to the camera's) and searching
    ``reach_mm`` and ``reach_deg`` round it. ``features`` name -> (3,) mm (default :func:`default_features`);
    ``expected``: the object rendered as the camera would see it (as :func:`find_points` takes it), to leave out
    edges without contrast."""
    prior = check_transform(prior_obj2cam, name="prior (obj2cam)")
    item = SceneItem(
        name,
        mesh,
        np.eye(4),
        color=tuple(color),
        features=default_features(mesh) if features is None else dict(features),
    )

    def look(start: np.ndarray) -> FoundPoints:
        if item.features:
            return find_points(
                image,
                intrinsics,
                item,
                start,
                expected=expected,
                reach_mm=reach_mm,
                reach_deg=reach_deg,
                edge_rms_px=PHOTO_EDGE_RMS_PX,
                by_colour=True,
            )
        return _edges_only(image, intrinsics, item, start, expected, reach_mm, reach_deg)

    located = _report(look(prior), intrinsics, prior, reach_mm, reach_deg)
    if located.status != "ok":
        return located
    # Starts round the prior (half the reach, along and across the line of sight): on a photo whose view is nearly
    # affine (a 250 px box at 1450 px focal) the outline fits as well 4 % nearer or further, turned to match, and
    # the edge fit's own covariance does not show it (2 mm in depth where starts ended 40 mm apart). The spread of
    # the starts that settle is added to the 1-sigma, and a start that ends beyond it is said.
    #
    # Then two starts from the answer itself, 4 % nearer and further: the outline scaled by 4 % each way. On a part
    # with printed or inner edges (the tutorial box's printed frame lies 10-15 px inside its outline) a fit that
    # took an inner edge for the outline, or the outline for an inner edge, finds the other one from there.
    fits = [located]
    for start in _starts_round(prior, reach_mm / 2.0, reach_deg / 2.0) + _depth_starts(
        located.obj2cam, RIVAL_DEPTH_SHARE
    ):
        other = _report(look(start), intrinsics, start, reach_mm, reach_deg)
        if other.status == "ok" and _within_reach(other.obj2cam, prior, reach_mm, reach_deg):
            fits.append(other)
    return _verdict(fits, mesh, intrinsics, prior)


RIVAL_DEPTH_SHARE = 0.04
"""How far nearer and further (a share of the distance) the answer is moved to look for a rival fit."""
RIVAL_SHARE = 0.02
"""A settled fit elsewhere on the image whose share of samples on their edges is within this of the answer's is a
rival (on OpenCV's box photo the fits of the box's outline hold 97.5-99 %, a fit 11 px off it 94-96 %; fits that
took the print for the outline, before the outline was found by colour, held 100 %)."""
AGREE_PX = 2.0
"""Settled fits whose outlines lie within this many pixels of each other (or within three times the edges' RMS) are
one answer: apart further, the photo holds two explanations and the answer is ``uncertain``. (On OpenCV's box photo,
whose lens nobody calibrated, fits of the box's own outline from different starts lie up to 3 px apart at 1.3 px
RMS; fits that took its print for its outline lay 12-35 px away.)"""


def _depth_starts(obj2cam: np.ndarray, share: float) -> list[np.ndarray]:
    out = []
    for sign in (-1.0, 1.0):
        start = obj2cam.copy()
        start[:3, 3] = obj2cam[:3, 3] * (1.0 + sign * share)
        out.append(start)
    return out


def image_distance_px(a: np.ndarray, b: np.ndarray, mesh, intrinsics: Intrinsics) -> float:
    """How far apart, px, poses ``a`` and ``b`` (both 4 x 4 obj2cam, mm) put what the camera sees of the mesh: the
    largest distance between the edge samples seen at ``a`` (its outline and creases) projected at each. Hidden
    points are left out: on a nearly affine view a turn traded for depth moves a hidden back corner 15 px while
    every seen edge stays within 3."""
    from calib_core.camera.projection import project_points
    from calib_core.vision.edge_samples import edge_points

    seen = edge_points(mesh, a, intrinsics)[0]
    if not len(seen):
        seen = np.asarray(mesh.vertices, dtype=float)[:: max(1, len(mesh.vertices) // 2000)]
    return float(
        np.max(np.linalg.norm(project_points(seen, a, intrinsics) - project_points(seen, b, intrinsics), axis=1))
    )


def _fit_quality(fit: Located) -> tuple[float, float]:
    return (fit.edge_share or 0.0, -(fit.edge_rms_px or np.inf))


def _within_reach(pose: np.ndarray, prior: np.ndarray, reach_mm: float, reach_deg: float) -> bool:
    moved = float(np.linalg.norm(pose[:3, 3] - prior[:3, 3]))
    return moved <= 3.0 * reach_mm and rotation_angle_deg(pose[:3, :3] @ prior[:3, :3].T) <= 3.0 * reach_deg


def _verdict(fits: list[Located], mesh, intrinsics: Intrinsics, prior: np.ndarray) -> Located:
    """The answer from the settled fits of every start: the one with the most samples on their edges (then the
    least RMS), its 1-sigma widened by the spread of the fits that put the object's seen edges where it does (within
    :data:`AGREE_PX` or three times its RMS). ``uncertain`` when a fit elsewhere in the image is about as good (its
    share on edges within :data:`RIVAL_SHARE` of the answer's): the photo then holds two explanations. A fit elsewhere
    that holds clearly fewer of its edges is a start that went astray, not a rival. Fits that agree in the image but
    not in depth (a nearly affine view) are one answer: their spread is in the 1-sigma."""
    from dataclasses import replace as with_fields

    best = max(fits, key=_fit_quality)
    bound = max(AGREE_PX, 3.0 * (best.edge_rms_px or 0.0))
    apart = [image_distance_px(best.obj2cam, f.obj2cam, mesh, intrinsics) for f in fits]
    agreeing = [f.obj2cam for f, d in zip(fits, apart) if d <= bound]
    rivals = [
        (d, f)
        for f, d in zip(fits, apart)
        if d > bound and (f.edge_share or 0.0) >= (best.edge_share or 0.0) - RIVAL_SHARE
    ]
    moved = float(np.linalg.norm(best.obj2cam[:3, 3] - prior[:3, 3]))
    turned = rotation_angle_deg(best.obj2cam[:3, :3] @ prior[:3, :3].T)
    located = with_fields(best, prior_moved_mm=round(moved, 3), prior_turned_deg=round(float(turned), 4))
    located = _with_spread(located, agreeing, len(fits))
    located = with_fields(
        located,
        extra={
            **located.extra,
            "starts_apart_px": round(max(apart), 2),
            "rival_apart_px": round(max(d for d, _ in rivals), 2) if rivals else None,
        },
    )
    if not rivals:
        return located
    d, rival = max(rivals, key=lambda r: r[0])
    return with_fields(
        located,
        status="uncertain",
        message=f"uncertain: another start settled with the object {d:.1f} px away in the image (more than {bound:.1f} "
        "px), "
        f"{100 * (rival.edge_share or 0.0):.0f} % of its samples on their edges against this answer's "
        f"{100 * (best.edge_share or 0.0):.0f} %: an inner, printed or neighbouring edge explains the outline about as "
        "well; " + located.message,
    )


def _starts_round(prior: np.ndarray, mm: float, deg: float) -> list[np.ndarray]:
    """Two starts: ``mm`` nearer and further along the line of sight to the object, each turned ``deg`` about an
    axis across it (the pair that trades depth for turn)."""
    from scipy.spatial.transform import Rotation

    sight = prior[:3, 3] / max(float(np.linalg.norm(prior[:3, 3])), 1e-9)
    across = np.cross(sight, [0.0, 1.0, 0.0])
    across = across / max(float(np.linalg.norm(across)), 1e-9)
    out = []
    for sign in (-1.0, 1.0):
        start = prior.copy()
        start[:3, 3] = prior[:3, 3] + sign * mm * sight
        start[:3, :3] = Rotation.from_rotvec(np.radians(sign * deg) * across).as_matrix() @ prior[:3, :3]
        out.append(start)
    return out


def _with_spread(located: Located, ends: list[np.ndarray], starts: int = 5) -> Located:
    """``located`` with its 1-sigma widened by the spread of the starts' ends (the standard deviation about their
    mean, per camera axis), and a word when they disagree beyond the edge fit's own 1-sigma (x3)."""
    from dataclasses import replace as with_fields
    from scipy.spatial.transform import Rotation

    if len(ends) < 2:
        return with_fields(
            located,
            message=located.message + f"; 1 of {starts} settled fits put it here: the 1-sigma is the edge fit's own",
        )
    t = np.array([e[:3, 3] for e in ends])
    turn = np.array([Rotation.from_matrix(e[:3, :3] @ ends[0][:3, :3].T).as_rotvec() for e in ends])
    spread_t, spread_r = t.std(axis=0, ddof=1), np.degrees(turn.std(axis=0, ddof=1))
    std_t = np.hypot(located.std_translation_mm, spread_t)
    std_r = np.hypot(located.std_rotation_deg, spread_r)
    apart = float(np.max(np.linalg.norm(t - t[0], axis=1)))
    note = f"; {len(ends)} of {starts} settled fits put it here, within {apart:.1f} mm of one another"
    if np.any(np.abs(t - t[0]).max(axis=0) > 3.0 * np.maximum(located.std_translation_mm, 1e-6)):
        note += (
            " (more than the edges' own 1-sigma allows: the photo fixes the pose less well than one fit says; the "
            "1-sigma includes the starts' spread)"
        )
    return with_fields(
        located,
        message=located.message + note,
        std_translation_mm=std_t,
        std_rotation_deg=std_r,
        extra={**located.extra, "starts_apart_mm": round(apart, 3)},
    )


def _edges_only(image, intrinsics, item, prior, expected, reach_mm, reach_deg) -> FoundPoints:
    """Find points' pose search and edge fit for an object without features: one dummy feature at its centre,
    reported as missed, so the same code runs."""
    centre = np.asarray(item.mesh.bounding_box.centroid, dtype=float)
    from calib_core.workcell.feature_kinds import FeatureKind

    item = SceneItem(
        item.name,
        item.mesh,
        item.item2world,
        color=item.color,
        features={"centre": centre},
        feature_kinds={"centre": FeatureKind("point")},
    )
    return find_points(
        image,
        intrinsics,
        item,
        prior,
        expected=expected,
        reach_mm=reach_mm,
        reach_deg=reach_deg,
        edge_rms_px=PHOTO_EDGE_RMS_PX,
        by_colour=True,
    )


def _report(
    found: FoundPoints, intrinsics: Intrinsics, prior: np.ndarray, reach_mm: float, reach_deg: float
) -> Located:
    edges = found.edges
    features = tuple(LocatedFeature(p.feature, p.uv_px, p.point_mm, p.confidence, p.why) for p in found.proposals)
    missed = tuple((m.feature, m.reason) for m in found.missed if m.feature != "centre")
    if edges is None or not edges.settled:
        why = found.message.replace(": pick the points by hand", "")
        return Located(
            "not found",
            f"{why}; give a prior nearer the object, or a larger reach",
            None,
            None,
            None,
            None if edges is None else edges.rms_px,
            None if edges is None else edges.inlier_share,
            0 if edges is None else edges.samples,
            features,
            missed,
            seconds=found.seconds,
        )
    moved = float(np.linalg.norm(edges.obj2cam[:3, 3] - prior[:3, 3]))
    turned = rotation_angle_deg(edges.obj2cam[:3, :3] @ prior[:3, :3].T)
    if moved > 3.0 * reach_mm or turned > 3.0 * reach_deg:
        # the search covered the reach round the prior; a fit that walked far beyond it found something else
        return Located(
            "not found",
            f"the edges settled {moved:.0f} mm and {turned:.1f} deg from the prior, beyond three times the reach "
            f"({reach_mm:g} mm, {reach_deg:g} deg) the search covered: give a prior nearer the object, or a larger "
            "reach",
            None,
            None,
            None,
            edges.rms_px,
            edges.inlier_share,
            edges.samples,
            (),
            missed,
            prior_moved_mm=round(moved, 3),
            prior_turned_deg=round(float(turned), 4),
            seconds=found.seconds,
        )
    std = np.sqrt(np.clip(np.diag(edges.covariance), 0.0, None))
    features_pose, apart = None, None
    if len(features) >= 4:
        solution = solve_pose(
            np.array([f.point_mm for f in features]),
            np.array([f.uv_px for f in features]),
            intrinsics,
            prior=edges.obj2cam,
        )
        if solution.status.value != "failed":
            features_pose = solution.obj2cam
            apart = round(float(np.linalg.norm(features_pose[:3, 3] - edges.obj2cam[:3, 3])), 3)
    message = (
        f"located by its edges: {edges.samples} samples, {100 * edges.inlier_share:.0f} % on their edges, RMS "
        f"{edges.rms_px:.2f} px; "
        f"{len(features)} features found" + (f", {len(missed)} not" if missed else "")
    )
    return Located(
        "ok",
        message,
        edges.obj2cam,
        np.degrees(std[:3]),
        std[3:],
        round(edges.rms_px, 3),
        round(edges.inlier_share, 3),
        edges.samples,
        features,
        missed,
        features_pose,
        apart,
        round(moved, 3),
        round(float(turned), 4),
        found.seconds,
    )
