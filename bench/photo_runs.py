"""The real-photo bench's runs and what each gives for one view (``bench/real_photos.py`` measures them; its targets,
truth checks and peers read them): from which prior the look starts and how far it searches, and the row scored."""

from __future__ import annotations

from dataclasses import dataclass

PRIORS = ((5.0, 1.0), (10.0, 3.0), (30.0, 10.0))
FROM_TRUTH = (0.0, 0.0)
"""The annotation itself as the prior: where the look ends when it starts at the truth says how far the image's edges,
the scanned mesh and the annotation agree, a bound on every row above."""
TRUTH_REACH = (5.0, 1.0)
"""How far the look searches round the truth (mm, deg) for the checks of what the truth is worth
(:mod:`bench.truth_checks`): a prior held that tightly pulls the fit towards the annotation."""
ROBOTS_REACH = (10.0, 3.0)
"""A robot's error (mm, deg)."""
BOUND_REACHES = (ROBOTS_REACH, (30.0, 10.0))
"""The truth also searched as far as these priors are off (mm, deg), its prior held as loosely as theirs, so that where
it ends is what the photo says round the annotation, beside where the look ends from that far off: the same share
within 5 px from both says the search is not what a miss lacks."""
RUNS = (
    tuple((prior, prior) for prior in PRIORS)
    + ((FROM_TRUTH, TRUTH_REACH),)
    + tuple((FROM_TRUTH, reach) for reach in BOUND_REACHES)
)
"""(prior's offset from the truth, reach searched), each (mm, deg)."""
VISIBLE_BINS = ((0.5, 0.7), (0.7, 0.9), (0.9, 1.01))
WRONG_OK_PX = 10.0
"""An answer called ``ok`` further than this from the truth (MSPD at 640 px width) is a wrong ``ok``."""


@dataclass
class Row:
    dataset: str
    prior: tuple[float, float]
    key: str
    status: str
    visible: float
    mspd_px: float
    mssd_mm: float
    t_mm: float
    r_deg: float
    diameter_mm: float
    seconds: float
    width: int
    centre_px: tuple[float, float] | None = None
    """Where the truth puts the object's centre in the image (px)."""
    centre_moved_px: tuple[float, float] | None = None
    """The answer's image of the object's centre less the truth's (px), when there is an answer."""
    colours_at: tuple[float | None, float | None] | None = None
    """How well the mesh's own colours agree with the photo at the answer and at the truth
    (:func:`bench.colour_agreement.colour_agreement`), when there is an answer."""
    points_sigma_px: float | None = None
    """The answer's stated 1-sigma of the object's points in the image (px, the image's own)."""
    apart_px: float | None = None
    """MSPD (px, the image's own) between this answer and the one the look gave started at the truth itself, both
    ``ok``: two of the look's own answers, no annotation in between."""
    apart_sigma_px: float | None = None
    """The two answers' stated 1-sigmas combined (the root of their squares' sum), px."""
    reach: tuple[float, float] | None = None
    """How far the look searched (mm, deg); ``None``: as far as the prior is off (the truth: :data:`TRUTH_REACH`)."""
    seed: str = ""
    """The seed word the prior was drawn with beside the view and distance (empty: the bench's own priors)."""
    obj_id: int | None = None
    """The data set's object id."""
    model_view: bool = False
    """Given the model's view as ``videocal locate`` renders it for a mesh whose samples are its creases (a CAD-like
    mesh), which the bench's own rows are not: :mod:`bench.command_path`."""

    @property
    def run(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(prior, reach), as in :data:`RUNS`."""
        if self.reach is not None:
            return self.prior, self.reach
        return self.prior, TRUTH_REACH if self.prior == FROM_TRUTH else self.prior

    @property
    def at_truth(self) -> bool:
        """Started at the truth, searching :data:`TRUTH_REACH` round it (what the truth checks compare with)."""
        return self.run == (FROM_TRUTH, TRUTH_REACH)

    @property
    def mspd_640_px(self) -> float:
        """The answer's MSPD at 640 px width (BOP's scale: a 1920 px photo's pixels count a third)."""
        return self.mspd_px * 640.0 / self.width


@dataclass(frozen=True)
class Tally:
    """What a list of rows came to: ``views``; ``within_5`` within MSPD 5 px (at 640 px width) whatever the status;
    ``ok``; ``ok_5_10`` called ``ok`` 5-10 px off; ``wrong_ok`` called ``ok`` over :data:`WRONG_OK_PX` off;
    ``uncertain``; ``not_found``."""

    views: int
    within_5: int
    ok: int
    ok_5_10: int
    wrong_ok: int
    uncertain: int
    not_found: int

    @staticmethod
    def of(rows: list[Row]) -> Tally:
        ok = [r.mspd_640_px for r in rows if r.status == "ok"]
        return Tally(
            views=len(rows),
            within_5=sum(r.mspd_640_px < 5.0 for r in rows),
            ok=len(ok),
            ok_5_10=sum(5.0 <= e <= WRONG_OK_PX for e in ok),
            wrong_ok=sum(e > WRONG_OK_PX for e in ok),
            uncertain=sum(r.status == "uncertain" for r in rows),
            not_found=sum(r.status == "not found" for r in rows),
        )
