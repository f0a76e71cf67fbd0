"""A look on any photograph: a known object's pose in a camera's frame from one image, its edges and features.

What the window does at a task location (Find points and the edge fit, :mod:`calib_core.look.find_points`),
on a photo of one object with nothing else known: the object's mesh, the camera's intrinsics and a rough pose
(the prior) to start from. So a look can be checked on real photographs (a phone photo of a box and its mesh),
not only on the simulated camera.

The pose reported is the edge fit's: hundreds of samples along the object's outline and creases, with its
covariance (each edge chain's samples taken as one measurement). The features found are reported with their
pixels and, when four or more agree, the pose they give on their own: two measurements that share no sample.
"""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import check_transform, rotation_angle_deg
from calib_core.scene import SceneItem
from calib_core.look.find_points import REACH_DEG, REACH_MM, find_points
from calib_core.look.found_points import FoundPoints
from calib_core.look.image_evidence import ImageEvidence
from calib_core.look.located import Located, LocatedFeature
from calib_core.look.pose_prior import PosePrior
from calib_core.look.unsettled_message import lines_up
from calib_core.look.locate_verdict import verdict

PHOTO_EDGE_RMS_PX = 1.5
"""The edge fit's settle bound on a photograph, px (with three quarters of the samples on their edges): a
photographed cardboard box fits its outline to 1.1-1.4 px (rounded edges, JPEG, an uncalibrated lens), where the
cell's camera is held to 0.5 px."""
PHOTO_WIDTH_PX = 640
"""The width at which :data:`PHOTO_EDGE_RMS_PX` holds as it is (a Kinect's, the webcam's: LM-O's and most photos')."""


def photo_rms_bound_px(width_px: int) -> float:
    """The edge fit's settle bound on a photograph ``width_px`` wide, px: :data:`PHOTO_EDGE_RMS_PX` up to
    :data:`PHOTO_WIDTH_PX`, and above it growing with the square root of the width (2.6 px at 1920). A wider photo
    spreads the same blur, the same JPEG blocks and the same rounded edges over more pixels: on HANDAL's 1920 x 1440
    photos the right answers settled at 1.04-1.49 px, against the bound, and a view found 3.9 px off its truth (at
    640 px width) with this bound had been refused at 1.53 px; from 10 mm / 3 deg 8 of 10 `ok` (was 7), from 30 mm /
    10 deg 4 (3), from the truth 9 (7), every `ok` within 5 px but one 9.7 px off (as before), none more than 10.
    Growing in proportion (4.5 px at 1920) would let a fit settle on clutter its edges only graze."""
    return PHOTO_EDGE_RMS_PX * max(1.0, width_px / PHOTO_WIDTH_PX) ** 0.5


MAX_DEFAULT_FEATURES = 64
"""A mesh of at most this many vertices (a box, a plate) gives its vertices as corner features by default."""


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
    """The pose of the object ``mesh`` (mm, its own frame) in ``image`` (h, w[, 3]) uint8 (or its
    :class:`~calib_core.look.image_evidence.ImageEvidence`) taken by a camera of
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

    believed = PosePrior(prior, reach_mm, reach_deg)
    evidence = ImageEvidence.of(image)  # one grey, gradient and edge map for every start

    target = item if item.features else _with_centre(item)  # (the same search for an object without features)

    def look(start: np.ndarray) -> FoundPoints:
        return find_points(
            evidence,
            intrinsics,
            target,
            start,
            expected=expected,
            reach_mm=reach_mm,
            reach_deg=reach_deg,
            edge_rms_px=photo_rms_bound_px(intrinsics.width),
            by_colour=True,
            prior=believed,
        )

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
    others = _starts_round(prior, reach_mm / 2.0, reach_deg / 2.0) + _depth_starts(located.obj2cam, RIVAL_DEPTH_SHARE)
    for start in others:
        other = _report(look(start), intrinsics, start, reach_mm, reach_deg)
        if other.status == "ok" and believed.holds(other.obj2cam):
            fits.append(other)
    return verdict(fits, mesh, intrinsics, prior, starts=1 + len(others))


RIVAL_DEPTH_SHARE = 0.04
"""How far nearer and further (a share of the distance) the answer is moved to look for a rival fit."""


def _depth_starts(obj2cam: np.ndarray, share: float) -> list[np.ndarray]:
    out = []
    for sign in (-1.0, 1.0):
        start = obj2cam.copy()
        start[:3, 3] = obj2cam[:3, 3] * (1.0 + sign * share)
        out.append(start)
    return out


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


def _with_centre(item: SceneItem) -> SceneItem:
    """``item`` with one feature at its mesh's centre (reported as missed): Find points' pose search and edge fit then
    run for an object without features."""
    from calib_core.workcell.feature_kinds import FeatureKind

    centre = np.asarray(item.mesh.bounding_box.centroid, dtype=float)
    return SceneItem(
        item.name,
        item.mesh,
        item.item2world,
        color=item.color,
        features={"centre": centre},
        feature_kinds={"centre": FeatureKind("point")},
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
            f"{why}; "
            + (
                "pick its points by hand in the window, or give a prior nearer it"
                if edges is not None and lines_up(edges)
                else "give a prior nearer the object, or a larger reach"
            ),
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
    if not PosePrior(prior, reach_mm, reach_deg).holds(edges.obj2cam):
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
        from calib_core.solver import solve_pose  # (its kernels load only for a look that found features)

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
        covariance=edges.covariance,
    )
