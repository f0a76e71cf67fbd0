"""The look's verdict from other draws of the priors: the same views, distances and angles, each prior drawn again with
another seed. A verdict tuned, knowingly or not, to the bench's own draw of priors keeps no wrong ``ok`` there and
shows them here: every wrong ``ok`` is named, with which of the two poses, the answer or the annotation, the scanned
mesh's own colours agree with better (the annotation has errors of its own the size of the 10 px line)."""

from __future__ import annotations

import numpy as np

from bench.photo_runs import WRONG_OK_PX, Row, Tally
from bench.truth_checks import COLOURS_APART

OTHER_SEEDS = ("a", "b", "c", "d", "e")
"""The seed words of the other draws (:func:`bench.real_views.view_prior`)."""
SEEDED_PRIORS = ((10.0, 3.0), (30.0, 10.0))
"""The priors (mm, deg) drawn again: a robot's error and a coarser one, each searched as far as it is off."""
SEEDED_RUNS = tuple((seed, prior) for seed in OTHER_SEEDS for prior in SEEDED_PRIORS)


def seeded_section(rows: list[Row]) -> list[str]:
    """A table per data set, prior and seed (answers, ``ok``, within 5 px, wrong ``ok``); each wrong ``ok`` named."""
    if not rows:
        return []
    out = [
        "| data set | prior | seed | views | within MSPD 5 px | ok | wrong ok (> 10 px) | uncertain | not found |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    wrong: list[Row] = []
    for name in sorted({r.dataset for r in rows}):
        for seed, (mm, deg) in SEEDED_RUNS:
            rs = [r for r in rows if r.dataset == name and r.seed == seed and r.prior == (mm, deg)]
            if not rs:
                continue
            bad = [r for r in rs if r.status == "ok" and r.mspd_640_px > WRONG_OK_PX]
            wrong += bad
            t = Tally.of(rs)
            out.append(
                f"| {name} | {mm:g} mm / {deg:g} deg | {seed} | {t.views} | {t.within_5} | {t.ok} | {t.wrong_ok} | "
                f"{t.uncertain} | {t.not_found} |"
            )
    answers = sum(r.status == "ok" for r in rows)
    out += ["", f"Wrong `ok` over these draws: {len(wrong)} of {answers} answers called `ok`."]
    for r in sorted(wrong, key=lambda r: r.mspd_640_px):
        out.append(
            f"- {r.key} (object {r.obj_id}, {100 * r.visible:.0f} % in sight), from {r.prior[0]:g} mm / "
            f"{r.prior[1]:g} deg, seed {r.seed}: {r.mspd_640_px:.1f} px off the annotation (at 640 px width), stated "
            f"1-sigma {_sigma_640(r)}; {_colour_word(r)}"
        )
    return out


def _sigma_640(r: Row) -> str:
    if r.points_sigma_px is None or not np.isfinite(r.points_sigma_px):
        return "none"
    return f"{r.points_sigma_px * 640.0 / r.width:.1f} px"


def _colour_word(r: Row) -> str:
    if r.colours_at is None or None in r.colours_at:
        return "the mesh carries no colours"
    answer, truth = r.colours_at
    if answer > truth + COLOURS_APART:
        return f"the mesh's colours agree better at the answer ({answer:.2f} against {truth:.2f})"
    if truth > answer + COLOURS_APART:
        return f"the mesh's colours agree better at the annotation ({truth:.2f} against {answer:.2f})"
    return f"the mesh's colours tell neither ({answer:.2f} at the answer, {truth:.2f} at the annotation)"
