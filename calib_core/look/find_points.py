"""Find points: the target's features located in a camera frame, to propose as pairs.

1. Predict every feature's pixel from the modelled camera pose; keep those in the image and not hidden
   by the target itself (a ray from the camera reaches the feature first).
2. Find roughly where the target is: camera poses within the robot's error of the modelled one,
   ranked by how well the target's edges lie on the image's (:mod:`calib_core.look.pose_hypotheses`).
3. Refine the pose on the image's gradients from the best few (:mod:`calib_core.look.edge_refinement`), in
   turn until one settles with three quarters of its samples on their edges (the image's noise can rank a
   wrong start first: a wrong minimum settles too, with about half); the fit with the most samples on
   their edges is kept, and nothing is proposed unless it settles with 60 % of them
   (:mod:`calib_core.look.fit_choice`).
4. Detect each feature by its kind (:mod:`calib_core.look.target_detectors`: with the model's view,
   a corner's edges and a circle's rim measured against it) in a window of three times the edges'
   scatter around its projection; drop detections more than 1 px from where the edges put them; a
   robust pose fit (sampled by confidence, PROSAC) rejects the remaining wrong ones. What survives is
   proposed with its confidence; what does not is listed with the reason. The edges run once more
   from the features' pose, and the fit with more samples on their edges is the one reported.

The result never moves anything: the operator accepts, rejects or drags the proposals.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.scene import SceneItem
from calib_core.look.edge_alignment import TRUNCATE_PX as EDGE_TRUNCATE_PX
from calib_core.look.edge_refinement import FINEST_WINDOW_PX, SETTLED_RMS_PX, EdgeFit
from calib_core.look.form_tolerance import form_error_px
from calib_core.look.unsettled_message import unsettled_message
from calib_core.look.halved_look import at_full_size, halved_view, halvings
from calib_core.look.edge_samples import edge_points
from calib_core.look.feature_detectors import Detection, NotDetected
from calib_core.look.found_points import FoundPoints, Missed, Proposal
from calib_core.look.fit_choice import EdgeFitting, best_settled_fit, fit_rank
from calib_core.look.image_evidence import ImageEvidence
from calib_core.look.in_view import MIN_SHOWN_SAMPLES, hidden_in_view, seen_unhidden, share_in_view
from calib_core.look.target_detectors import TargetDetectors
from calib_core.look.pose_prior import PosePrior
from calib_core.look.pose_hypotheses import TRUNCATE_PX as HYPOTHESIS_TRUNCATE_PX, rank_starts
from calib_core.workcell.feature_kinds import CORNER, FeatureKind

from calib_core.look.search_reach import REACH_DEG, REACH_MM  # noqa: E402 (named apart: a command's --help reads them)

_EDGE_AGREEMENT_PX = 1.0
_SIGMA_PX = 0.5
# starts tried at most: on one frame of the demo the right one ranked fourth, the first three settling 1.6-1.9 mm off at
# 55 %
_STARTS = 8
OBJECT_TURN_SHARE = 0.5
"""With a prior (a look on a photo), the ranked starts also turn the object this share of the reach's angle each way
across the line of sight (HANDAL's tools from 30 mm / 10 deg off, three seeds of priors: within 5 px 7 -> 13 of 30)."""
_REUSE_PX = 0.25  # the second pass's view serves the detectors when its fit moved the target less than this
_RECHECK_SEARCH_PX = 3.0  # the features' pose is within a pixel or so of the edges'
_AGREE_PX = 0.2  # the edges' run from the features' pose only when the two put a feature further apart


def _not_in_view(item: SceneItem, names: list[str], t0: float, why: str) -> FoundPoints:
    return FoundPoints(
        item.name,
        False,
        f"{item.name} is not in the camera's view where the model puts it ({why}, even allowing for the robot's "
        "error): move the robot to where the camera sees it (Go to task) and look again",
        missed=tuple(Missed(n, "not in the camera's view at the modelled pose") for n in names),
        seconds=time.perf_counter() - t0,
    )


def search_radius_px(
    points_mm: np.ndarray,
    obj2cam: np.ndarray,
    intrinsics: Intrinsics,
    reach_mm: float = REACH_MM,
    reach_deg: float = REACH_DEG,
) -> float:
    """How far (px) the target may lie from where a camera at ``obj2cam`` sees it, when the camera may be
    ``reach_mm`` and ``reach_deg`` off: a move across the line of sight shifts a point at depth z by
    f reach / z (the target's nearer half counts), a turn by f reach in radians."""
    z = points_mm @ obj2cam[2, :3] + obj2cam[2, 3]
    z = z[z > 1.0]
    f = max(intrinsics.fu, intrinsics.fv)
    near = float(np.percentile(z, 25)) if len(z) else 1e9
    return f * (reach_mm / near + np.radians(reach_deg))


def find_points(
    image: np.ndarray | ImageEvidence,
    intrinsics: Intrinsics,
    item: SceneItem,
    obj2cam_model: np.ndarray,
    *,
    kinds: dict[str, FeatureKind] | None = None,
    reach_mm: float = REACH_MM,
    reach_deg: float = REACH_DEG,
    expected=None,
    edge_rms_px: float = SETTLED_RMS_PX,
    by_colour: bool = False,
    prior: PosePrior | None = None,
) -> FoundPoints:
    """Locate ``item``'s features in ``image`` (h, w[, 3]) uint8 (or its :class:`ImageEvidence`, shared with other
    looks at the same image), seen by a camera that the model puts at
    ``obj2cam_model`` (4, 4: the item's frame to the camera's, mm). ``kinds`` by feature name (default:
    the item's own, corner when absent). ``expected(obj2cam, box_px) -> image``: the cell rendered as this
    camera would see it with the item at ``obj2cam`` (lens distortion included; only the box
    (u0, v0, u1, v1) px need be, :meth:`~calib_core.render.model_view.ModelView.render`): edges it shows no
    contrast on are not searched for. ``reach_mm`` and ``reach_deg``: how far the true camera may be
    from the modelled one (the robot's error), which bounds the search. ``edge_rms_px``: the edge fit's settle bound
    (:data:`~calib_core.look.edge_refinement.SETTLED_RMS_PX` for the cell's camera; coarser for a photo).
    ``by_colour``: the outline found where the target's colours end (:mod:`~calib_core.look.region_model`),
    not at the strongest gradient, on a colour image where the target's colours tell it from its surroundings.
    ``prior``: where the target is believed to be, a measurement of every edge fit (a look on a photograph); given,
    the fit starts from ``obj2cam_model`` itself, then coarse to fine from there, before the ranked starts."""
    t0 = time.perf_counter()
    kinds = item.feature_kinds if kinds is None else kinds
    names = list(item.features)
    if not names:
        return FoundPoints(item.name, False, f"component {item.name!r} has no features to find")
    evidence = ImageEvidence.of(image)
    form_px = form_error_px(item, obj2cam_model, intrinsics)
    count = halvings(form_px, intrinsics.width)
    if count:
        camera = intrinsics
        for _ in range(count):
            evidence, camera = evidence.half_with(camera)
        smaller = find_points(
            evidence,
            camera,
            item,
            obj2cam_model,
            kinds=kinds,
            reach_mm=reach_mm,
            reach_deg=reach_deg,
            expected=halved_view(expected, count),
            edge_rms_px=edge_rms_px,
            by_colour=by_colour,
            prior=prior,
        )
        why = (
            f"its stated form tolerance, {item.form_tolerance_mm:g} mm, is {form_px:.1f} px in the whole image, more "
            f"than the {FINEST_WINDOW_PX:g} px the edge fit averages over"
        )
        return replace(at_full_size(smaller, count, why), seconds=time.perf_counter() - t0)
    points = np.array([item.features[n] for n in names], dtype=float)
    uv_model = project_points(points, obj2cam_model, intrinsics)
    radius_px = search_radius_px(item.mesh.vertices, obj2cam_model, intrinsics, reach_mm, reach_deg)
    z = points @ obj2cam_model[2, :3] + obj2cam_model[2, 3]
    visible = (
        (z > 0) & intrinsics.contains(uv_model, margin_px=-radius_px) & seen_unhidden(item.mesh, points, obj2cam_model)
    )
    missed = {n: "hidden or outside the image at the modelled pose" for n, v in zip(names, visible) if not v}
    if share_in_view(item.mesh, obj2cam_model, intrinsics, radius_px) == 0.0:
        # no pose within the robot's error shows it: no search can find it, and no pick by hand either
        return _not_in_view(item, names, t0, "it lies outside the image, or behind the camera")

    # edges of colour as well as of lightness (an orange top on a tan table has one grey)
    distance = evidence.edge_distance(EDGE_TRUNCATE_PX)
    detectors = TargetDetectors(evidence, item, intrinsics, expected)
    candidates = [i for i in range(len(names)) if visible[i]]
    t_edges = time.perf_counter()
    samples, _, _, _ = edge_points(
        item.mesh,
        obj2cam_model,
        intrinsics,
        detectors.expected_magnitude(obj2cam_model) if expected is not None else None,
    )
    if (
        expected is not None
        and len(samples) < MIN_SHOWN_SAMPLES
        and hidden_in_view(samples, item.mesh, obj2cam_model, intrinsics)
    ):
        return _not_in_view(item, names, t0, f"only {len(samples)} samples of its edges would show")
    ranking: list[np.ndarray] = []

    def ranked() -> list[np.ndarray]:
        if not ranking:
            ranking.extend(
                rank_starts(
                    evidence.edge_distance(HYPOTHESIS_TRUNCATE_PX),
                    intrinsics,
                    samples,
                    obj2cam_model,
                    reach_mm,
                    reach_deg,
                    keep=_STARTS,
                    # a photo's prior is an error of the object itself, moved and turned about its own origin
                    # (PosePrior): close up or long, a turn of the object changes its outline's shape, which no move
                    # or turn of the camera in the grid makes (decision 158)
                    object_turn_deg=0.0 if prior is None else OBJECT_TURN_SHARE * reach_deg,
                )
            )
        return ranking

    colour = evidence.colour if by_colour else None
    fitting = EdgeFitting(
        evidence,
        intrinsics,
        item.mesh,
        detectors,
        expected is not None,
        edge_rms_px,
        colour,
        prior,
        evidence.colour_bins if colour is not None else None,
    )
    edge_fit = best_settled_fit(fitting, obj2cam_model, ranked, prior is not None)
    edge_seconds = time.perf_counter() - t_edges
    # where the image puts the target's centre against where the model does
    centre = item.mesh.vertices.mean(axis=0)[None]
    seen_at = edge_fit.obj2cam if edge_fit.settled else ranked()[0]
    shift = project_points(centre, seen_at, intrinsics)[0] - project_points(centre, obj2cam_model, intrinsics)[0]
    if not edge_fit.settled:
        # Not there, or the edges did not settle: detections in wide windows would lock onto neighbouring
        # edges, and a wrong proposal costs the operator more than a pick by hand.
        return FoundPoints(
            item.name,
            False,
            unsettled_message(item, edge_fit, distance, intrinsics),
            missed=tuple(Missed(n, missed.get(n, "the target's pose was not found")) for n in names),
            offset_px=shift,
            seconds=time.perf_counter() - t0,
            edges=edge_fit,
            edge_seconds=edge_seconds,
        )
    start = _detection_start(detectors, expected is not None, points, edge_fit.obj2cam, intrinsics)
    # after the edges, each feature is within a few tenths of a pixel of its prediction: a window of three
    # times the edges' scatter keeps a detector off the neighbouring edge (a boss's base beside its rim)
    radius = float(np.clip(3.0 * edge_fit.sigma_px, 1.0, 3.0))
    first = {i: detectors.detect(kinds.get(names[i], CORNER), points[i], start, radius) for i in candidates}
    if edge_fit.converged:
        first = _agreeing_with_edges(first, points, edge_fit, intrinsics)
    pose, fit = _robust_fit(first, points, intrinsics, start)
    if pose is not None and _moved_px(points, pose, edge_fit.obj2cam, intrinsics) > _AGREE_PX:
        # The edges can settle where every feature still passes the 1 px gate and yet off the pose the
        # features put them at (a plate cut by the image's border, its faint rims holding the rest:
        # 1.1 mm off with 0.1 mm sigma, 84 % on their edges; from the features' pose 96 %): the edges
        # again from there, and the fit with more samples on their edges is kept. Where the two poses
        # put every feature within _AGREE_PX of each other there is nothing to find.
        t_across = time.perf_counter()
        across = fitting.refine(pose, search_px=_RECHECK_SEARCH_PX, shown_at=start)
        if across.settled and fit_rank(across) > fit_rank(edge_fit):
            edge_fit = across
        edge_seconds += time.perf_counter() - t_across
    if pose is None:
        for i, d in first.items():
            missed.setdefault(names[i], d.reason if isinstance(d, NotDetected) else "no pose fits the detections")
        return FoundPoints(
            item.name,
            False,
            f"{item.name}: only {sum(isinstance(d, Detection) for d in first.values())} features detected, too few for "
            "a pose: "
            "pick the points by hand, or Calibrate on edges (its edges settled)",
            missed=tuple(Missed(n, r) for n, r in missed.items()),
            offset_px=shift,
            seconds=time.perf_counter() - t0,
            edges=edge_fit,
            edge_seconds=edge_seconds,
        )
    proposals = _proposals(first, fit, pose, names, points, kinds, intrinsics, missed)
    found = len(proposals) >= 4
    message = (
        f"{len(proposals)} of {len(names)} features of {item.name} found"
        + (f"; {len(missed)} not: see the list" if missed else "")
        if found
        else f"{item.name}: only {len(proposals)} features found, too few: pick the points by hand"
    )
    return FoundPoints(
        item.name,
        found,
        message,
        tuple(proposals),
        tuple(Missed(n, r) for n, r in missed.items()),
        shift,
        pose if found else None,
        time.perf_counter() - t0,
        edge_fit,
        edge_seconds,
    )


def _detection_start(
    detectors: TargetDetectors, has_view: bool, points: np.ndarray, fitted: np.ndarray, intrinsics: Intrinsics
) -> np.ndarray:
    """The pose the detectors measure from: the edges' ``fitted`` one, or the pose of the model's view they last
    rendered when it lies within :data:`_REUSE_PX` of it (a render saved: a quarter of the time close up)."""
    shown = detectors.rendered_pose()
    if (
        has_view
        and shown is not None
        and _moved_px(np.vstack([points, detectors.box_corners]), shown, fitted, intrinsics) < _REUSE_PX
    ):
        return shown
    return fitted


def _agreeing_with_edges(detections: dict, points: np.ndarray, edge_fit: EdgeFit, intrinsics: Intrinsics) -> dict:
    """``detections`` with those far from where the edges put their feature not detected. The edges (hundreds of
    samples) know the pose better than any one detection: a detection far from them found something else (a
    silhouette in front of a corner); within the edges' own scatter too (a photographed box's rounded corners sit
    1.5-4.5 px from its edges' lines)."""
    uv_edges = project_points(points, edge_fit.obj2cam, intrinsics)
    agreement = max(_EDGE_AGREEMENT_PX, 2.0 * edge_fit.sigma_px)
    out = dict(detections)
    for i, d in detections.items():
        if isinstance(d, Detection) and np.linalg.norm(d.uv_px - uv_edges[i]) > agreement:
            out[i] = NotDetected(
                f"what was detected lies {np.linalg.norm(d.uv_px - uv_edges[i]):.1f} px from where the target's edges "
                "put it (another edge in front of it?)"
            )
    return out


def _proposals(
    detections: dict,
    kept: dict[int, bool],
    pose: np.ndarray,
    names: list[str],
    points: np.ndarray,
    kinds: dict[str, FeatureKind],
    intrinsics: Intrinsics,
    missed: dict[str, str],
) -> list[Proposal]:
    """The detections the robust fit at ``pose`` kept, as proposals; the others' reasons added to ``missed``."""
    proposals = []
    uv_final = project_points(points, pose, intrinsics)
    for i, d in detections.items():
        if isinstance(d, NotDetected):
            missed[names[i]] = d.reason
            continue
        residual = float(np.linalg.norm(d.uv_px - uv_final[i]))
        if not kept.get(i, False):
            missed[names[i]] = f"rejected by the pose fit: {residual:.1f} px from where the other features put it"
            continue
        proposals.append(
            Proposal(
                names[i], kinds.get(names[i], CORNER).kind, d.uv_px, points[i].copy(), d.confidence, residual, d.why
            )
        )
    return proposals


def _moved_px(points_mm: np.ndarray, a: np.ndarray, b: np.ndarray, intrinsics: Intrinsics) -> float:
    """How far (px) the points (n, 3) of the target move in the image between poses ``a`` and ``b`` (4, 4), at most."""
    return float(
        np.max(
            np.linalg.norm(project_points(points_mm, a, intrinsics) - project_points(points_mm, b, intrinsics), axis=1)
        )
    )


def _robust_fit(
    detections: dict, points: np.ndarray, intrinsics: Intrinsics, prior: np.ndarray
) -> tuple[np.ndarray | None, dict[int, bool]]:
    """The pose of the detections (robust, sampled best-confidence first) and which it keeps."""
    found = [(i, d) for i, d in detections.items() if isinstance(d, Detection)]
    if len(found) < 4:
        return None, {}
    from calib_core.solver import solve_pose  # (its kernels load only for a look that detected features)
    from calib_core.solver.errors import SolverInputError

    idx = [i for i, _ in found]
    uv = np.array([d.uv_px for _, d in found])
    confidence = np.array([d.confidence for _, d in found])
    try:
        solution = solve_pose(
            points[idx], uv, intrinsics, prior=prior, robust=True, sigma_px=_SIGMA_PX, confidence=confidence
        )
    except SolverInputError:
        return None, {}
    if solution.status.value == "failed":
        return None, {}
    return solution.obj2cam, {i: not bool(out) for i, out in zip(idx, solution.outliers)}
