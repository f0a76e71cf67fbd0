"""The look's targets on real photographs, each beside what the real-photo bench measured (``bench/real_photos.py``):
the share within MSPD 5 px from a robot's error and from a coarser one, no wrong ``ok``, the time a 640 x 480 view."""

from __future__ import annotations

import numpy as np

from bench.photo_runs import BOUND_REACHES, FROM_TRUTH, PRIORS, WRONG_OK_PX

VIEW_SECONDS = 1.0
"""The most a 640 x 480 view may take (median, one process)."""


def _within_5(rows) -> str:
    if not rows:
        return "-"
    within = sum(r.mspd_640_px < 5.0 for r in rows)
    return f"{100 * within / len(rows):.0f} % ({within} of {len(rows)})"


def _share_met(rows, least: float) -> bool | None:
    if not rows:
        return None
    return sum(r.mspd_640_px < 5.0 for r in rows) >= least * len(rows)


def target_rows(rows, seeded=()) -> list[str]:
    """A table of the targets (``rows``: the bench's :class:`~bench.photo_runs.Row`; the runs from the truth itself
    count for none; ``seeded``: the rows from other draws of the priors, :mod:`bench.photo_seeds`, for the wrong
    ``ok``), one column a data set, and whether each is met everywhere it was measured."""
    sets = sorted({r.dataset for r in rows})
    if not sets:
        return []

    def pick(name, prior, lo, hi):
        return [r for r in rows if r.dataset == name and r.prior == prior and lo <= r.visible < hi]

    lines = []
    checks = []
    for label, prior, lo, hi, least in (
        ("within MSPD 5 px from 10 mm / 3 deg, 70 % or more in sight", (10.0, 3.0), 0.7, 1.01, 0.95),
        ("within MSPD 5 px from 10 mm / 3 deg, 50-70 % in sight", (10.0, 3.0), 0.5, 0.7, 0.80),
        ("within MSPD 5 px from 30 mm / 10 deg, 70 % or more in sight", (30.0, 10.0), 0.7, 1.01, 0.80),
    ):
        cells = [_within_5(pick(name, prior, lo, hi)) for name in sets]
        met = [_share_met(pick(name, prior, lo, hi), least) for name in sets]
        checks.append((f"{label}: {100 * least:.0f} %", cells, met))
    wrong = []
    for name in sets:
        counted = [r for r in rows if r.dataset == name and r.prior in PRIORS]
        wrong.append(sum(r.status == "ok" and r.mspd_640_px > WRONG_OK_PX for r in counted))
    checks.append(("wrong `ok` (over 10 px) from every prior: 0", [f"{w}" for w in wrong], [w == 0 for w in wrong]))
    if seeded:
        others = [
            sum(r.status == "ok" and r.mspd_640_px > WRONG_OK_PX for r in seeded if r.dataset == name) for name in sets
        ]
        checks.append(
            (
                "wrong `ok` (over 10 px) from the other draws of the priors: 0",
                [f"{w}" for w in others],
                [w == 0 for w in others],
            )
        )
    seconds, met_time = [], []
    for name in sets:
        small = [r.seconds for r in rows if r.dataset == name and r.width <= 640 and r.prior in PRIORS]
        seconds.append(f"{np.median(small):.2f} s" if small else "- (no 640 x 480 views)")
        met_time.append(None if not small else bool(np.median(small) <= VIEW_SECONDS))
    checks.append((f"a 640 x 480 view, median over every prior: {VIEW_SECONDS:g} s", seconds, met_time))
    lines += ["| target | " + " | ".join(sets) + " | met |", "|---|" + "---|" * len(sets) + "---|"]
    for label, cells, met in checks:
        said = [m for m in met if m is not None]
        verdict = "-" if not said else ("yes" if all(said) else "no")
        lines.append(f"| {label} | " + " | ".join(cells) + f" | {verdict} |")
    # not targets: their bounds, the look started at the truth itself searching as far as the prior was off
    for reach in BOUND_REACHES:
        bound = [
            _within_5([r for r in rows if r.dataset == name and r.run == (FROM_TRUTH, reach) and r.visible >= 0.7])
            for name in sets
        ]
        if any(cell != "-" for cell in bound):
            lines.append(
                f"| (a bound, not a target) within MSPD 5 px started at the truth itself, searching {reach[0]:g} mm / "
                f"{reach[1]:g} deg, 70 % or more in sight | " + " | ".join(bound) + " | - |"
            )
    return lines
