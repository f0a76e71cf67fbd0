"""Which of a look's edge fits is kept: with a prior, a fit that walked beyond three times its reach is no answer
however many samples it holds; the starts' fits are given here as recorded, so the choice alone is what is tested."""

from __future__ import annotations

import numpy as np

from calib_core.look.edge_refinement import EdgeFit
from calib_core.look.fit_choice import best_settled_fit
from calib_core.look.pose_prior import PosePrior


def _at(x_mm: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = [x_mm, 0.0, 900.0]
    return pose


def _settled(pose: np.ndarray, samples: int, share: float) -> EdgeFit:
    return EdgeFit(pose, 0.3, 0.3, samples, np.eye(6), True, np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), share)


class _RecordedFits:
    """What the edge fit gave from each start (keyed by the start's position), and the look's prior."""

    def __init__(self, fits: dict[float, EdgeFit], prior: PosePrior | None):
        self.fits, self.prior, self.asked = fits, prior, []

    def refine(self, start: np.ndarray, **_) -> EdgeFit:
        self.asked.append(float(start[0, 3]))
        return self.fits[float(start[0, 3])]


def _fits() -> dict[float, EdgeFit]:
    # from the first start the fit slid 40 mm onto a neighbour's edges, holding more samples than the object's own
    far, near = _at(40.0), _at(4.0)
    return {
        0.0: _settled(far, 120, 0.95),
        40.0: _settled(far, 120, 0.95),
        1.0: _settled(near, 60, 0.9),
        4.0: _settled(near, 60, 0.9),
    }


def test_a_fit_beyond_three_times_the_reach_loses_to_one_within_it():
    fits = _RecordedFits(_fits(), PosePrior(_at(0.0), sigma_mm=10.0, sigma_deg=3.0))
    chosen = best_settled_fit(fits, _at(0.0), lambda: [_at(0.0), _at(1.0)], False)
    assert chosen.obj2cam[0, 3] == 4.0
    assert fits.asked == [0.0, 1.0, 4.0]  # the second start tried, and its fit refined again


def test_without_a_prior_the_fit_with_most_samples_on_their_edges_is_kept():
    fits = _RecordedFits(_fits(), None)
    chosen = best_settled_fit(fits, _at(0.0), lambda: [_at(0.0), _at(1.0)], False)
    assert chosen.obj2cam[0, 3] == 40.0
    assert fits.asked == [0.0, 40.0]  # it settled with most of its samples: the search ended there


def test_a_photos_settle_bound_grows_with_the_square_root_of_its_width_above_640_px():
    from calib_core.look.locate import PHOTO_EDGE_RMS_PX, photo_rms_bound_px

    assert photo_rms_bound_px(320) == photo_rms_bound_px(640) == PHOTO_EDGE_RMS_PX
    assert photo_rms_bound_px(2560) == 2.0 * PHOTO_EDGE_RMS_PX
    assert photo_rms_bound_px(1920) == np.sqrt(3.0) * PHOTO_EDGE_RMS_PX
