"""What the truth is worth, for the real-photo bench's page (``bench/real_photos.py``): where a look started at the
annotation settles against it, whether an answer's stated 1-sigma covers what two of the look's own answers scatter,
and which of answer and annotation the scanned mesh's own colours support. Each from the bench's rows, known answers in
tests/bench."""

from __future__ import annotations

import numpy as np

from bench.photo_runs import FROM_TRUTH, PRIORS, WRONG_OK_PX, Row


def with_start_agreement(view_rows: list[Row], answers: dict, points, symmetries, view) -> list[Row]:
    """One view's rows, each ``ok`` answer from a prior other than the truth with how far it lies from the ``ok``
    answer started at the truth (``answers``: :attr:`Row.run` -> obj2cam) and the two stated 1-sigmas combined."""
    from dataclasses import replace

    from calib_core.datasets.pose_errors import mspd

    (at_truth,) = [r for r in view_rows if r.at_truth]
    if at_truth.status != "ok" or at_truth.points_sigma_px is None:
        return view_rows
    out = []
    for r in view_rows:
        if r.prior != FROM_TRUTH and r.status == "ok" and r.points_sigma_px is not None:
            r = replace(
                r,
                apart_px=mspd(answers[r.run], answers[at_truth.run], points, symmetries, view.intrinsics),
                apart_sigma_px=float(np.hypot(r.points_sigma_px, at_truth.points_sigma_px)),
            )
        out.append(r)
    return out


def stated_sigma(rows: list[Row]) -> list[str]:
    """Whether the stated 1-sigma of the points covers what it should, per data set and prior: the distance between
    two of the look's own ``ok`` answers (from the prior and from the truth) in units of their combined 1-sigma, and
    the distance to the annotation in units of the answer's own (median and 90th percentile, and how many beyond
    3). The first holds no annotation; the second holds the annotation's error too."""
    out = []
    for name in sorted({r.dataset for r in rows}):
        for prior in PRIORS:
            rs = [r for r in rows if r.dataset == name and r.prior == prior and r.apart_px is not None]
            if len(rs) < 5:
                continue
            own = np.array([r.apart_px / max(r.apart_sigma_px, 1e-9) for r in rs])
            annotation = np.array([r.mspd_px / max(r.points_sigma_px, 1e-9) for r in rs])  # (both the image's px)
            out.append(
                f"| {name} | {prior[0]:g} mm / {prior[1]:g} deg | {len(rs)} | {np.median(own):.2f}, "
                f"{np.percentile(own, 90):.2f} | {int((own > 3).sum())} | {np.median(annotation):.2f}, "
                f"{np.percentile(annotation, 90):.2f} | {int((annotation > 3).sum())} |"
            )
    if not out:
        return []
    return [
        "| data set | prior | views `ok` from both | apart from the answer started at the truth, in combined 1-sigmas "
        "(median, 90 %) | beyond 3 | off the annotation, in the answer's 1-sigma (median, 90 %) | beyond 3 |",
        "|---|---|---|---|---|---|---|",
        *out,
    ]


def annotation_offset(rows: list[Row]) -> list[str]:
    """Where the look settles when it starts at the truth, against the truth, per data set: the mean shift of the
    object's centre in the image (px, with its standard error) over the views called ``ok``, and how much of the
    sideways shift grows with the distance from the image's centre (a scale: px a px). A mean several standard errors
    from zero is the annotation lying off the objects as the photos show them, the same way in every view, not the
    look's scatter."""
    out = []
    for name in sorted({r.dataset for r in rows}):
        rs = [r for r in rows if r.dataset == name and r.at_truth and r.status == "ok" and r.centre_moved_px]
        if len(rs) < 8:
            continue
        moved = np.array([r.centre_moved_px for r in rs])
        at = np.array([r.centre_px for r in rs])
        mean, error = moved.mean(axis=0), moved.std(axis=0, ddof=1) / np.sqrt(len(rs))
        width = rs[0].width
        scale = np.polyfit(at[:, 0] - width / 2.0, moved[:, 0], 1)[0]
        out.append(
            f"- {name}, {len(rs)} views called `ok` from the truth: the object's centre moves a mean "
            f"({mean[0]:+.2f} +- {error[0]:.2f}, {mean[1]:+.2f} +- {error[1]:.2f}) px (right, down; 1 standard error), "
            f"scattering {moved[:, 0].std(ddof=1):.1f} and {moved[:, 1].std(ddof=1):.1f} px a view; sideways it moves "
            f"{100 * scale:+.2f} % of its distance from the image's middle."
        )
    return out


COLOURS_APART = 0.02
"""Agreements of the mesh's colours closer than this are neither pose's."""
OFF_BY_PX = ((0.0, 5.0), (5.0, WRONG_OK_PX), (WRONG_OK_PX, np.inf))


def colour_evidence(rows: list[Row]) -> list[str]:
    """For the answers (every prior, any status) in each band of MSPD from the annotation, per data set: at how many
    the scanned mesh's own colours, which the look does not read, agree better with the photo at the answer than at
    the annotation, at how many the other way, at how many neither (within :data:`COLOURS_APART`); the bands in px at
    640 px width, as a wrong ``ok`` is counted. Where the answer is far off the annotation should win: that row says
    what the measure is worth."""
    out = []
    for name in sorted({r.dataset for r in rows}):
        for lo, hi in OFF_BY_PX:
            pairs = [
                r.colours_at
                for r in rows
                if r.dataset == name
                and lo <= r.mspd_640_px < hi
                and r.colours_at is not None
                and None not in r.colours_at
            ]
            if not pairs:
                continue
            answer = sum(a > t + COLOURS_APART for a, t in pairs)
            truth = sum(t > a + COLOURS_APART for a, t in pairs)
            band = f"more than {lo:g} px" if not np.isfinite(hi) else f"{lo:g}-{hi:g} px"
            out.append(f"| {name} | {band} | {len(pairs)} | {answer} | {truth} | {len(pairs) - answer - truth} |")
    if not out:
        return []
    return [
        "| data set | answer off the annotation (MSPD) | answers | colours agree better at the answer | at the "
        "annotation | neither |",
        "|---|---|---|---|---|---|",
        *out,
    ]
