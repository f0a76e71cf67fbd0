"""The verdict of a look on a photograph over the fits of its starts: one answer, its 1-sigma widened by how far the
fits that agree with it spread, ``uncertain`` when another fit explains the image about as well elsewhere."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import rotation_angle_deg
from calib_core.look.located import Located

RIVAL_SHARE = 0.02
"""A settled fit elsewhere on the image whose share of samples on their edges is within this of the answer's is a
rival (on OpenCV's box photo the fits of the box's outline hold 97.5-99 %, a fit 11 px off it 94-96 %; fits that
took the print for the outline, before the outline was found by colour, held 100 %). The least margin: see
:data:`RIVAL_SIGMAS`."""
RIVAL_SIGMAS = 2.0
"""A settled fit elsewhere is a rival while its share of samples on their edges is within this many standard errors
of the answer's (each share a proportion of its own samples: ``sqrt(p (1 - p) / n)``). On a cluttered photo where
only 83-86 % of 75-95 samples lie on their edges the shares themselves are uncertain by 4-6 %: a fit 33 px away that
held 83 % against the answer's 86 % is not clearly worse, and the answer it lost to was 16 px off the truth
(LM-O's driller from 30 mm / 10 deg off)."""
AGREE_PX = 3.0
"""Settled fits whose outlines lie within this many pixels of each other (or within three times the edges' RMS) are
one answer, their spread part of its 1-sigma: apart further, the photo holds two explanations and the answer is
``uncertain``. (On OpenCV's box photo, whose lens nobody calibrated, fits of the box's own outline from different
starts lie up to 3 px apart at 1.3 px RMS; fits that took its print for its outline lay 12-35 px away.)"""


NEAR_RIVAL_PX = 10.0
"""A rival at most this far (px at 640 px width) is the same outline fitted a few pixels apart, not another edge: on
LM-O from 30 mm / 10 deg off, 9 of 13 rivals lay 3.5-8 px from the answer with as many samples on their edges (a
rounded object's outline fixes its turn loosely), the other 4 at 22-34 px; on OpenCV's box photo fits that took its
print for its outline lay 12-35 px away."""
SETTLED_STARTS = 3
"""The least number of the look's starts whose fits settle (on the answer or elsewhere) for an answer to be ``ok``:
where the photo holds the object firmly, starts half the reach off the prior settle too. On the real photos (LM-O
and HANDAL from 10 mm / 3 deg and 30 mm / 10 deg, six draws of the priors) every ``ok`` answer the look itself got
wrong by more than 14 px (four: 16-63 px, a white glue bottle fitted up into the white drill behind it, an ape onto
the print of a book cover of its own brown) stood on one or two settled fits; so did 28 of the 470 within 10 px,
``uncertain`` now (decision 161). Starts that settle elsewhere with clearly fewer samples on edges count: on
OpenCV's box photo they settle on its print, a sign of a photo full of edges, not of a fragile answer."""
POINTS_SIGMA_PX = 5.0
"""The largest 1-sigma of the object's points in the image (px at 640 px width) of an answer called ``ok``: an
outline that fixes where an object is seen but not its turn (a rounded scanned object, LM-O's ape and can) leaves
its points free by more, and such answers were 10-29 px off their truth where the verdict had called them ``ok``."""


def image_distance_px(a: np.ndarray, b: np.ndarray, mesh, intrinsics: Intrinsics) -> float:
    """How far apart, px, poses ``a`` and ``b`` (both 4 x 4 obj2cam, mm) put what the camera sees of the mesh: the
    largest distance between the edge samples seen at ``a`` (its outline and creases) projected at each. Hidden
    points are left out: on a nearly affine view a turn traded for depth moves a hidden back corner 15 px while
    every seen edge stays within 3."""
    from calib_core.camera.projection import project_points
    from calib_core.look.edge_samples import edge_points

    seen = edge_points(mesh, a, intrinsics)[0]
    if not len(seen):
        seen = np.asarray(mesh.vertices, dtype=float)[:: max(1, len(mesh.vertices) // 2000)]
    return float(
        np.max(np.linalg.norm(project_points(seen, a, intrinsics) - project_points(seen, b, intrinsics), axis=1))
    )


def points_sigma_px(mesh, obj2cam: np.ndarray, covariance: np.ndarray, intrinsics: Intrinsics) -> float:
    """How far the object's points may lie from where ``obj2cam`` (4, 4, mm) puts them in the image, 1-sigma px: the
    largest over the mesh's vertices (at most 500 of them, evenly) of the root of the trace of each vertex's pixel
    covariance, propagated from the pose's ``covariance`` (6, 6: rotation vector rad, translation mm, camera frame).
    An outline that fixes the object's place but not its turn (a round silhouette) leaves the hidden and inner points
    free: what the pose error BOP scores (MSPD) measures, and the fit's own samples do not."""
    from calib_core.camera.projection import project_points
    from calib_core.look.edge_refinement import perturbed

    if covariance is None or not np.all(np.isfinite(covariance)):
        return float("inf")
    vertices = np.asarray(mesh.vertices, dtype=float)
    vertices = vertices[:: max(1, len(vertices) // 500)]
    base = project_points(vertices, obj2cam, intrinsics)
    J = np.empty((len(vertices), 2, 6))
    for k in range(6):
        step = np.zeros(6)
        h = 1e-5 if k < 3 else 1e-3
        step[k] = h
        J[:, :, k] = (project_points(vertices, perturbed(obj2cam, step), intrinsics) - base) / h
    per_point = np.einsum("mik,kl,mil->m", J, covariance, J)
    return float(np.sqrt(np.max(np.clip(per_point, 0.0, None))))


def fit_quality(fit: Located) -> tuple[float, float]:
    return (fit.edge_share or 0.0, -(fit.edge_rms_px or np.inf))


def holds_about_as_many(other: Located, best: Located) -> bool:
    """Whether fit ``other`` holds about as many of its samples on their edges as ``best``: within
    :data:`RIVAL_SHARE`, or within :data:`RIVAL_SIGMAS` standard errors of the two shares' difference."""
    p, q = best.edge_share or 0.0, other.edge_share or 0.0
    error = np.sqrt(p * (1.0 - p) / max(best.edge_samples, 1) + q * (1.0 - q) / max(other.edge_samples, 1))
    return q >= p - max(RIVAL_SHARE, RIVAL_SIGMAS * float(error))


def verdict(fits: list[Located], mesh, intrinsics: Intrinsics, prior: np.ndarray, starts: int = 5) -> Located:
    """The answer from the settled fits of every start: the one with the most samples on their edges (then the
    least RMS), its 1-sigma widened by the spread of the fits that put the object's seen edges where it does (within
    :data:`AGREE_PX` or three times its RMS). ``uncertain`` when a fit elsewhere in the image is about as good (its
    share on edges not clearly less than the answer's, :func:`holds_about_as_many`): the photo then holds two
    explanations. A fit elsewhere
    that holds clearly fewer of its edges is a start that went astray, not a rival; more fits than agree with the
    answer settling together elsewhere (:func:`crowd_elsewhere`) are no strays, and the answer is ``uncertain``. Fits
    that agree in the image but not in depth (a nearly affine view) are one answer: their spread is in the 1-sigma.
    An answer when fewer than :data:`SETTLED_STARTS` of the look's ``starts`` settled is ``uncertain`` too: it
    stands on too few fits."""
    from dataclasses import replace as with_fields

    best = max(fits, key=fit_quality)
    bound = max(AGREE_PX, 3.0 * (best.edge_rms_px or 0.0))
    apart = [image_distance_px(best.obj2cam, f.obj2cam, mesh, intrinsics) for f in fits]
    agreeing = [f.obj2cam for f, d in zip(fits, apart) if d <= bound]
    rivals = [(d, f) for f, d in zip(fits, apart) if d > bound and holds_about_as_many(f, best)]
    moved = float(np.linalg.norm(best.obj2cam[:3, 3] - prior[:3, 3]))
    turned = rotation_angle_deg(best.obj2cam[:3, :3] @ prior[:3, :3].T)
    located = with_fields(best, prior_moved_mm=round(moved, 3), prior_turned_deg=round(float(turned), 4))
    located = with_spread(located, agreeing, starts)
    if located.covariance is not None:
        located = with_fields(
            located, points_sigma_px=points_sigma_px(mesh, located.obj2cam, located.covariance, intrinsics)
        )
    located = with_fields(
        located,
        extra={
            **located.extra,
            "starts_apart_px": round(max(apart), 2),
            "rival_apart_px": round(max(d for d, _ in rivals), 2) if rivals else None,
        },
    )
    sigma_bound = POINTS_SIGMA_PX * intrinsics.width / 640.0
    # (no group elsewhere can outnumber the answer's while the fits elsewhere do not: the distances left unmeasured)
    outnumbered = len(fits) - len(agreeing) > len(agreeing)
    crowd = crowd_elsewhere(fits, apart, bound, mesh, intrinsics) if outnumbered and not rivals else []
    if len(crowd) > len(agreeing):
        other = max(crowd, key=fit_quality)
        d = image_distance_px(best.obj2cam, other.obj2cam, mesh, intrinsics)
        return with_fields(
            located,
            status="uncertain",
            rival_obj2cam=other.obj2cam,
            message=f"uncertain: {len(crowd)} of {len(fits)} settled fits put the object together {d:.1f} px away in "
            f"the image, {len(agreeing)} here; this answer holds more of its samples on their edges "
            f"({100 * (best.edge_share or 0.0):.0f} % against {100 * (other.edge_share or 0.0):.0f} %), but starts "
            "that end together elsewhere are another explanation of the photo, not starts gone astray; "
            + located.message,
        )
    if not rivals:
        if len(fits) < SETTLED_STARTS:
            return with_fields(
                located,
                status="uncertain",
                message=f"uncertain: {len(fits)} of the look's {starts} starts settled ({len(agreeing)} here), where "
                f"an answer called ok stands on at least {SETTLED_STARTS}: the others ended beyond the reach or did "
                "not settle, so the photo does not hold the object firmly (its colours those of what is behind it, "
                "or a print of its colour there?); check it against the photo; " + located.message,
            )
        if located.points_sigma_px is not None and located.points_sigma_px > sigma_bound:
            return with_fields(
                located,
                status="uncertain",
                message="uncertain: the outline fixes where the object is seen, but not where its points are: they "
                f"may lie {located.points_sigma_px:.1f} px from where this answer puts them (1-sigma, more than "
                f"{sigma_bound:.1f} px); " + located.message,
            )
        return located
    d, rival = max(rivals, key=lambda r: r[0])
    why = (
        "the outline holds the object only to within about that"
        if d <= NEAR_RIVAL_PX * intrinsics.width / 640.0
        else "an inner, printed or neighbouring edge explains the outline about as well"
    )
    return with_fields(
        located,
        status="uncertain",
        rival_obj2cam=rival.obj2cam,
        message=f"uncertain: another start settled with the object {d:.1f} px away in the image (more than {bound:.1f} "
        "px), "
        f"{100 * (rival.edge_share or 0.0):.0f} % of its samples on their edges against this answer's "
        f"{100 * (best.edge_share or 0.0):.0f} %: {why}; " + located.message,
    )


def crowd_elsewhere(
    fits: list[Located], apart: list[float], bound: float, mesh, intrinsics: Intrinsics
) -> list[Located]:
    """The largest group of ``fits`` (each ``apart`` px from the answer, beyond its ``bound``) that agree with one
    another: each within :data:`AGREE_PX` (or three times its own RMS) of the group's first. Starts that settle
    together away from the answer are another explanation of the photo, however clearly fewer of their samples lie
    on edges: on a HANDAL photo from 30 mm / 10 deg off, three starts put a spoon together 24 px (at 640 px width)
    from an answer that held 94 % of its samples on edges against their 76-80 %, and that answer, the only fit there,
    was the one 43 px off its truth (its handle's outline ended midway along the real handle)."""
    elsewhere = [f for f, d in zip(fits, apart) if d > bound]
    if len(elsewhere) < 2:
        return elsewhere[:1]
    groups = []
    for f in elsewhere:
        reach = max(AGREE_PX, 3.0 * (f.edge_rms_px or 0.0))
        groups.append(
            [g for g in elsewhere if g is f or image_distance_px(f.obj2cam, g.obj2cam, mesh, intrinsics) <= reach]
        )
    return max(groups, key=len)


def with_spread(located: Located, ends: list[np.ndarray], starts: int = 5) -> Located:
    """``located`` with its 1-sigma widened by the spread of the ends of those of the look's ``starts`` that settled
    on it (the standard deviation about their mean, per camera axis), and a word when they disagree beyond the edge
    fit's own 1-sigma (x3)."""
    from dataclasses import replace as with_fields
    from scipy.spatial.transform import Rotation

    if len(ends) < 2:
        return with_fields(
            located,
            message=located.message + f"; 1 of {starts} starts settled here: the 1-sigma is the edge fit's own",
        )
    t = np.array([e[:3, 3] for e in ends])
    turn = np.array([Rotation.from_matrix(e[:3, :3] @ ends[0][:3, :3].T).as_rotvec() for e in ends])
    spread_t, spread_r = t.std(axis=0, ddof=1), np.degrees(turn.std(axis=0, ddof=1))
    covariance = located.covariance
    if covariance is not None:
        # the ends' scatter as a covariance of the same six motions (turn rad, then translation mm), about their mean
        # (a step turns the translation too: t' = R(w) t + v)
        moves = t - Rotation.from_rotvec(turn).apply(ends[0][:3, 3])
        motions = np.column_stack([turn, moves])
        covariance = covariance + np.cov(motions, rowvar=False, ddof=1)
    std_t = np.hypot(located.std_translation_mm, spread_t)
    std_r = np.hypot(located.std_rotation_deg, spread_r)
    apart = float(np.max(np.linalg.norm(t - t[0], axis=1)))
    note = f"; {len(ends)} of {starts} starts settled here, within {apart:.1f} mm of one another"
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
        covariance=covariance,
        extra={**located.extra, "starts_apart_mm": round(apart, 3)},
    )
