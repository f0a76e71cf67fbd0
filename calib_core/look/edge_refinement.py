"""Model-based refinement: the target's CAD edges aligned to the image's gradients (the approach of
RAPID and of ViSP's model-based edge tracker).

Samples every few pixels along the edges the camera sees at the current estimate
(:mod:`calib_core.look.edge_samples`); for each,
the strongest gradient along the edge's normal within a window ("moving edges"); a robust
Gauss-Newton step on the pose that moves every sample along its normal onto its edge (Tukey weights,
scale from the median absolute deviation); the window shrinks as the pose converges. Edges the model
says have no contrast (where a rendered view of the cell, if given, shows no gradient) are left out:
two dark faces meeting make no edge to find, and a search there would lock onto the nearest one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, project_points
from calib_core.solver.clustered_covariance import clustered_scatter
from calib_core.look.edge_samples import MIN_STRENGTH as _MIN_STRENGTH
from calib_core.look.edge_samples import edge_model
from calib_core.look.colour_contrast import gradient_magnitude
from calib_core.look.feature_detectors import search_normals
from calib_core.look.pose_prior import PosePrior
from calib_core.look.region_model import MIN_CONTRAST, RegionModel

_TUKEY = 4.685


SETTLED_RMS_PX = 0.5
"""The largest RMS of a settled edge fit by default, px: the simulated camera's edges fit to 0.1-0.4 px, and a fit
coarser than that there is a poor one (admitting up to 1.5 px let such views into the robot's identification:
a grasp 0.48 mm off where 0.1 is the target). A photographed cardboard box (OpenCV's pose tutorial: rounded edges,
JPEG, a lens nobody calibrated) fits its outline to 1.1-1.4 px with 88-100 % of its samples on their edges:
``videocal locate`` gives a coarser bound (:data:`calib_core.look.locate.PHOTO_EDGE_RMS_PX`)."""
COARSE_FIT_SHARE = 0.75
"""The share of samples on their edges a fit coarser than 0.5 px must hold (under a coarser bound): on that photo a
start 150 mm off settled on the print and the table at 1.46 px with 51 % (and seven "corners" agreeing with it);
the right fits held 88-100 %."""


@dataclass(frozen=True)
class EdgeFit:
    """``obj2cam`` (4, 4) the refined pose (mm); ``rms_px`` the weighted RMS of the samples' normal
    offsets; ``sigma_px`` their robust scale; ``samples`` used in the last step; ``covariance`` (6, 6)
    of (rotation vector rad, translation mm) from the last step's normal equations, the samples of each
    edge chain taken as one measurement (their offsets share the edge's error) and never less than
    ``sigma_px`` over independent samples gives (``covariance_independent``), and with the outline found by colour
    the pose's own doubt about where the edge is (:attr:`outline_bias`);
    ``converged``; ``edges_px`` (m, 2) the image edge points found, ``offsets_px`` (m,) their offsets
    along the normals and ``residuals_px`` (m, 2) as vectors (image edge minus the model's edge, at the
    pose before the last step), for drawing and for the solution's residuals."""

    obj2cam: np.ndarray
    rms_px: float
    sigma_px: float
    samples: int
    covariance: np.ndarray
    converged: bool
    edges_px: np.ndarray
    offsets_px: np.ndarray
    residuals_px: np.ndarray
    inlier_share: float
    """The share of the model's edge samples that found their image edge in the last step (weight > 0):
    a fit that settled on a few samples (a wrong minimum) has a low one."""
    covariance_independent: np.ndarray | None = None
    """(6, 6) as ``covariance`` with every sample taken as independent (``sigma_px^2 H^-1``):
    ``covariance`` takes each edge chain's samples as one measurement as well, and is never less."""
    rms_bound_px: float = SETTLED_RMS_PX
    """The largest RMS at which this fit may count as settled (what the caller asked of its images)."""
    outline_bias: np.ndarray | None = None
    """(6,) rotation vector rad, translation mm: how far the pose would move if the outline found by colour were where
    the strongest gradient lies near each sample instead (after the whole outline's shift), ``None`` when the outline
    was not found by colour. Both are estimates of the same edge that err apart (the colours end inward of a lit
    bevel, a print line lies near an edge), and their disagreement is no noise that averages away over the samples:
    ``covariance`` holds its outer product."""
    min_share: float = 0.5
    """The least share of the samples on their edges at which a fit within 0.5 px counts as settled. Find points,
    which proposes pairs from the fit, asks 60 %: a wrong minimum can settle within 0.3 px holding about half of them
    (the demo's frame 12: 52-56 %, 1.6-1.9 mm off, where the right pose holds 90 %; the least right fit of the
    Find points bench held 65 %)."""

    px_scale: float = 1.0
    """The image's pixels to one of the image the fit ran on (2 for a fit on the image halved, its pixel figures given
    in the whole image's): what :attr:`settled` scales its 0.5 px by."""

    @property
    def settled(self) -> bool:
        """Converged, and either within 0.5 px RMS (of the image it ran on) with at least ``min_share`` of the samples
        on their edges, or within its ``rms_bound_px`` with :data:`COARSE_FIT_SHARE` of them (a coarser fit must hold
        more of its edges)."""
        if not self.converged:
            return False
        return (self.rms_px <= 0.5 * self.px_scale and self.inlier_share >= self.min_share) or (
            self.rms_px <= self.rms_bound_px and self.inlier_share >= COARSE_FIT_SHARE
        )


FINEST_WINDOW_PX = 2.0
"""The search along each sample's normal narrows, as the fit settles, to this many pixels either side: an edge further
from the model's than this (a part's bend off its CAD) drops out of the fit."""
CREASES_JOIN_PX = 2.0
"""With the outline found by colour, the creases join the fit once its search window is this narrow, px."""
CREASES_AGREE_PX = 0.75
"""... and only when their median offset from where the outline puts them is at most this, px."""
COLOUR_SNAP_PX = 1.5
"""How far from where the colours end the outline's strongest gradient is sought, px, to measure the colour step's
offset from the edge (the print a gradient search is misled by lies further inside: 10-15 px on a printed box)."""
MIN_REGION_SEPARATION = 0.2
"""The least :attr:`~calib_core.look.region_model.RegionModel.separation` at which the outline is found by
colour: below it the object's colours are too much its surroundings' to tell the two apart."""
RESAMPLE_VIEW_DEG = 1.0
"""A fit with contour samples takes them again once the camera sees the object from this much another direction (in the
object's frame): a smooth rim's samples taken a turn ``a`` ago lie off the rim by ``r (1 - cos a)``, 0.006 mm for a
40 mm radius at 1 deg (an uneven one's by more: LM-O's cat from 10 mm / 3 deg off ended 4.7 px from its truth taking its
samples again every degree, 5.1 px every two). A turn about the line of sight and a move along it change no rim (a fit
took them again at every degree of any turn and every 2 mm of any move: a third of a look's time); a depth change of
2 % does (the tangent cone narrows)."""
RESAMPLE_DEPTH_SHARE = 0.02


def _seen_otherwise(a: np.ndarray, b: np.ndarray, centre_mm: np.ndarray) -> bool:
    """Whether a camera at pose ``b`` (4, 4, obj2cam, mm) sees the object from a direction :data:`RESAMPLE_VIEW_DEG`
    or more from ``a``'s, or from a distance :data:`RESAMPLE_DEPTH_SHARE` different, as seen from the object's
    ``centre_mm`` (3,) (its frame)."""
    seen_a = -a[:3, :3].T @ a[:3, 3] - centre_mm
    seen_b = -b[:3, :3].T @ b[:3, 3] - centre_mm
    na, nb = float(np.linalg.norm(seen_a)), float(np.linalg.norm(seen_b))
    if na <= 0.0 or nb <= 0.0:
        return True
    cos = float(np.clip(seen_a @ seen_b / (na * nb), -1.0, 1.0))
    return bool(np.degrees(np.arccos(cos)) > RESAMPLE_VIEW_DEG or abs(nb / na - 1.0) > RESAMPLE_DEPTH_SHARE)


def perturbed(obj2cam: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """``obj2cam`` (4, 4, mm) moved by ``xi`` (6,): the rotation vector (rad) turning it about the camera's origin,
    then the translation (mm), camera frame: the step every edge fit, its Jacobians and the pose prior share."""
    out = obj2cam.copy()
    out[:3, :3] = Rotation.from_rotvec(xi[:3]).as_matrix() @ obj2cam[:3, :3]
    out[:3, 3] = Rotation.from_rotvec(xi[:3]).as_matrix() @ obj2cam[:3, 3] + xi[3:]
    return out


def normal_jacobian(
    points_mm: np.ndarray, obj2cam: np.ndarray, normals: np.ndarray, intrinsics: Intrinsics
) -> np.ndarray:
    """The derivative (m, 6) of each point's (m, 3, object frame, mm) pixel along its unit normal
    (m, 2) in the pose's six small motions (the rotation vector in rad, then the translation in mm,
    both in the camera frame, applied as :func:`perturbed` does). The pixel's derivative in the
    camera-frame point (central differences through the lens, three directions) times the point's in
    the motion (``-[X]x`` for a turn, the identity for a move)."""
    X = points_mm @ obj2cam[:3, :3].T + obj2cam[:3, 3]
    h = 1e-3  # mm, at 100-1000 mm: the lens's curvature is far below the pixel's
    d_uv = np.empty((len(X), 2, 3))
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        d_uv[:, :, k] = (project(X + step, intrinsics) - project(X - step, intrinsics)) / (2 * h)
    d_offset = np.einsum("mi,mik->mk", normals, d_uv)  # (m, 3): the normal offset per mm of the point
    return np.column_stack([np.cross(X, d_offset), d_offset])  # n . D (w x X) = (X x (n D)) . w


def refine_to_edges(
    grey: np.ndarray,
    intrinsics: Intrinsics,
    mesh,
    obj2cam: np.ndarray,
    *,
    expected_magnitude: np.ndarray | None = None,
    search_px: float = 8.0,
    iterations: int = 30,
    magnitude: np.ndarray | None = None,
    rms_bound_px: float = SETTLED_RMS_PX,
    colour: np.ndarray | None = None,
    prior: PosePrior | None = None,
    colour_bins: np.ndarray | None = None,
) -> EdgeFit:
    """Refine ``obj2cam`` (the mesh's frame to the camera's, mm) so that the mesh's edges lie on the
    image's; ``expected_magnitude`` (h, w) the :func:`gradient_magnitude` of the cell rendered at
    ``obj2cam``, to leave out edges without contrast; ``rms_bound_px`` the fit's settle bound (:attr:`EdgeFit.settled`);
    ``magnitude``: ``grey``'s :func:`gradient_magnitude`, when the caller has it. ``colour``: the image in RGB
    (h, w, 3) uint8; given, the outline's samples are found where the object's colours end
    (:mod:`calib_core.look.region_model`) when its colours tell it from its surroundings, not at the strongest
    gradient (print, texture and clutter have gradients too). ``prior``: where the object is believed to be, as one
    more measurement (:class:`~calib_core.look.pose_prior.PosePrior`), which keeps the fit from walking along what
    the edges hardly fix. ``colour_bins``: ``colour``'s
    :attr:`~calib_core.look.image_evidence.ImageEvidence.colour_bins`, when the caller has them."""
    magnitude = gradient_magnitude(grey) if magnitude is None else magnitude
    by_colour = colour is not None and colour.ndim == 3
    model = edge_model(mesh, obj2cam, intrinsics, expected_magnitude, whole_outline=by_colour)
    pts, far, clearance, chain, outward, from_outline = (
        model.points,
        model.far,
        model.clearance,
        model.chain,
        model.outward,
        model.from_outline,
    )
    regions = None
    if colour is not None and colour.ndim == 3:
        regions = RegionModel.from_image(colour, *model.silhouette, bins=colour_bins)
        if regions is not None and regions.separation < MIN_REGION_SEPARATION:
            regions = None  # the object's colours are its surroundings' too: the gradients are all there is
    pose = obj2cam.copy()
    sampled_at = pose
    centre = np.asarray(mesh.vertices, dtype=float).mean(axis=0)
    window = search_px
    sigma, rms, converged = 1.0, np.inf, False
    H = np.eye(6)
    edges, offsets, vectors = np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2))
    share = 0.0
    previous_xi, damping = None, 1.0
    creases_join = None
    gap = J_gap = None  # along each sample's normal: the gradient near the colour step, less the step (px)
    for it in range(iterations):
        if from_outline and _seen_otherwise(sampled_at, pose, centre):
            # a smooth surface's rim is where its surface turns away from this pose's camera: taken again
            model = edge_model(mesh, pose, intrinsics, expected_magnitude, whole_outline=by_colour)
            pts, far, clearance, chain, outward, from_outline = (
                model.points,
                model.far,
                model.clearance,
                model.chain,
                model.outward,
                model.from_outline,
            )
            sampled_at = pose
        if len(pts) < 12:
            break
        uv = project_points(pts, pose, intrinsics)
        d = project_points(far, pose, intrinsics) - uv
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
        normals = np.column_stack([-d[:, 1], d[:, 0]])
        found, strength, inside = search_normals(magnitude, uv, normals, window)
        ok = inside & (strength >= _MIN_STRENGTH)
        counted = np.ones(len(uv), dtype=bool)  # the samples the fit's share on its edges is of
        gap = None
        if regions is not None and outward.any():
            on_outline = outward != 0
            out_normals = normals[on_outline] * outward[on_outline, None]
            step, contrast, step_inside = regions.step_edges(uv[on_outline], out_normals, window)
            # Where the colours end lies inward of the edge: the blurred pixels astride it are mixed colours, likelier
            # the surroundings' than the object's (a dark fixture on a lit floor: 0.25 px plain, 0.6 px with a softer
            # lens and a ring light, which put a flat plate's fit 2 mm off in depth and kept its creases from
            # agreeing). One shift for the whole outline: the median distance to the strongest gradient near each
            # step (a print or grain nearer than the edge moves a few samples, not the median).
            snapped, snap_strength, snap_inside = search_normals(magnitude, step, out_normals, COLOUR_SNAP_PX)
            snap = snap_inside & step_inside & (snap_strength >= _MIN_STRENGTH)
            if snap.sum() >= 12:
                shift = float(np.median(np.einsum("ij,ij->i", snapped[snap] - step[snap], out_normals[snap])))
                step = step + shift * out_normals
            gap = np.zeros(len(uv))
            gap_on_outline = np.zeros(len(step))
            gap_on_outline[snap] = np.einsum("ij,ij->i", snapped[snap] - step[snap], normals[on_outline][snap])
            gap[on_outline] = gap_on_outline
            found[on_outline] = step
            # The outline alone brings the pose near, as the region-based trackers fit: a crease between two of the
            # object's faces has its colours on both sides, and on a printed part the strongest gradient within a
            # wide window is as often the print's (a frame 12 mm inside a box's edges pulled the pose 3 deg off its
            # outline). The creases join once the window is at its finest, where the print cannot reach them; they
            # sharpen the turn (a fixture on the simulated camera: 0.12 deg off by its outline alone, 0.01 with them).
            creases = ok & ~on_outline
            if creases_join is None and window <= CREASES_JOIN_PX and creases.any():
                # decided once: only creases that agree with where the outline has put the pose (a crease whose
                # nearest gradient is the print's lies px off all along it; the fixture's lie within a few tenths)
                r_creases = np.einsum("ij,ij->i", found[creases] - uv[creases], normals[creases])
                creases_join = bool(np.median(np.abs(r_creases)) <= CREASES_AGREE_PX)
            ok = creases & bool(creases_join)
            ok[on_outline] = step_inside & (contrast >= MIN_CONTRAST)
            counted = on_outline
        # while the window is wide, only the samples with no other edge inside it (a few, far apart,
        # bring the pose near; the crowded ones join as it shrinks)
        clear = ok & (clearance > window)
        ok = clear if clear.sum() >= max(12, 0.2 * ok.sum()) else ok
        if ok.sum() < 12:
            break
        r = np.einsum("ij,ij->i", found - uv, normals)
        mad = 1.4826 * float(np.median(np.abs(r[ok] - np.median(r[ok]))))
        sigma = max(mad, 0.05)
        c = _TUKEY * sigma
        wts = np.where(ok & (np.abs(r) < c), (1 - (r / c) ** 2) ** 2, 0.0)
        J = normal_jacobian(pts, pose, normals, intrinsics)
        J_chain, J_gap = chain, gap  # (the samples may be taken again before the loop ends: the covariance is of these)
        H = J.T @ (wts[:, None] * J)
        g = J.T @ (wts * r)
        if prior is not None:
            # the edges' residuals are px with unit weights: the prior's, in units of their scale
            H_prior, g_prior = prior.normal_equations(pose)
            H, g = H + sigma**2 * H_prior, g + sigma**2 * g_prior
        try:
            xi = np.linalg.solve(H + 1e-9 * np.eye(6) * np.trace(H), g)
        except np.linalg.LinAlgError:
            break
        if previous_xi is not None and xi @ H @ previous_xi < -0.5 * (xi @ H @ xi):
            # The step turned back on the last one: samples jumping between two pixels (an aliased or
            # quantised edge) make a two-cycle that plain Gauss-Newton never leaves. Halve the steps
            # from here on, and the pose settles between the two.
            damping *= 0.5
        previous_xi = xi
        xi = damping * xi
        pose = perturbed(pose, xi)
        rms = float(np.sqrt(np.sum(wts * r**2) / max(np.sum(wts), 1e-9)))
        edges, offsets, vectors = found[ok], r[ok], (r[:, None] * normals)[ok]
        share = float(np.mean(wts[counted] > 0)) if counted.any() else 0.0
        moved_px = float(np.max(np.abs(J @ xi))) if len(J) else 0.0
        at_finest = window <= FINEST_WINDOW_PX
        # coarse to fine: wrong matches fall away as it shrinks
        window = max(FINEST_WINDOW_PX, min(0.7 * window, 3.0 * sigma + 1.0))
        # Settled when the samples stop moving; at the finest window a step under a tenth of the
        # noise is samples trading places at the window's rim (a cycle, not a descent).
        if it > 0 and (moved_px < 0.01 or (at_finest and moved_px < 0.1 * sigma)):
            converged = True
            break
    bias = None
    try:
        H_inv = np.linalg.inv(H)
        independent = sigma**2 * H_inv
        covariance = (
            independent if len(offsets) == 0 else H_inv @ clustered_scatter(J, wts * r, J_chain, sigma**2 * H) @ H_inv
        )
        if J_gap is not None and len(offsets):
            bias = H_inv @ (J.T @ (wts * J_gap))
            covariance = covariance + np.outer(bias, bias)
    except np.linalg.LinAlgError:
        independent = covariance = np.full((6, 6), np.nan)
    return EdgeFit(
        pose,
        rms,
        sigma,
        len(offsets),
        covariance,
        converged,
        edges,
        offsets,
        vectors,
        share,
        independent,
        rms_bound_px,
        outline_bias=bias,
    )
