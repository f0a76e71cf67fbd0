"""The leave-one-view-out check of a robot identification, on linear fits whose answer is known."""

from __future__ import annotations

import numpy as np

from calib_core.robot_calibration.left_out_views import left_out_ratio


def _fit(views: int, parameters: int, rows_per_view: int, seed: int) -> float:
    """A linear least squares where each view says six numbers (its rows span six directions, as a camera pose's) and
    its rows share errors (as a view's corners share its pose's), fitted; the ratio of its left-out predictions to
    what it leaves."""
    rng = np.random.default_rng(seed)
    J = np.vstack([rng.normal(size=(rows_per_view, 6)) @ rng.normal(size=(6, parameters)) for _ in range(views)])
    view_of = np.repeat(np.arange(views), rows_per_view)
    shared = np.vstack([rng.normal(size=(rows_per_view, 6)) @ rng.normal(size=6) for _ in range(views)]).ravel()
    y = shared + 0.1 * rng.normal(size=len(view_of))
    x, *_ = np.linalg.lstsq(J, y, rcond=None)
    return left_out_ratio(J, y - J @ x, view_of, np.ones(len(y), dtype=bool))


def test_many_views_for_few_parameters_predict_a_left_out_view_about_as_well_as_the_fit():
    assert np.median([_fit(60, 4, 20, s) for s in range(5)]) < 1.2


def test_views_that_each_fix_parameters_of_their_own_are_said_to_be_fitted_to_their_own_errors():
    """12 views saying six numbers each, 60 parameters: the fit all but passes through every view."""
    assert np.median([_fit(12, 60, 20, s) for s in range(5)]) > 1.5
    assert np.median([_fit(12, 60, 20, s) for s in range(5)]) > np.median([_fit(12, 24, 20, s) for s in range(5)])


def test_a_view_left_out_is_predicted_exactly_as_refitting_without_it_does():
    """The deleted residuals from the hat matrix are those of the fit without the view (two ways)."""
    rng = np.random.default_rng(1)
    J = rng.normal(size=(40, 3))
    y = rng.normal(size=40)
    view_of = np.repeat(np.arange(8), 5)
    x, *_ = np.linalg.lstsq(J, y, rcond=None)
    r = y - J @ x
    refit = []
    for g in range(8):
        keep = view_of != g
        xg, *_ = np.linalg.lstsq(J[keep], y[keep], rcond=None)
        refit.append(y[~keep] - J[~keep] @ xg)
    expected = np.sqrt(np.mean(np.concatenate(refit) ** 2)) / np.sqrt(np.mean(r**2))
    assert abs(left_out_ratio(J, r, view_of, np.ones(40, dtype=bool)) - expected) < 1e-9
