"""Whether a robot identification bends the geometry to its own views: each view left out of the fit, predicted from
the fit's Jacobian (the deleted residuals of a linearised least squares, a view at a time), against what the fit
leaves it. Near 1 when the views are many for the parameters; large when each view's own errors are fitted."""

from __future__ import annotations

import numpy as np

OVERFIT_RATIO = 1.5
"""How much further off (RMS) a view left out of the fit is predicted than the fit leaves it, beyond which the result
says it bends the geometry to the views' errors. Measured: the simulated cold cell's 12 board and 9 component views,
38 parameters, 1.14 (the parameters within their 3-sigma); 12 real views of a Franka, 24 parameters, 1.79 (0.33 px
left against the corners' 0.29 px, where its recorded poses disagree by 3-6 mm)."""


def left_out_ratio(J: np.ndarray, residuals: np.ndarray, view_of: np.ndarray, kept: np.ndarray) -> float:
    """The RMS of every view's residuals predicted with that view left out of the fit, over the RMS the fit leaves
    (the deleted-residuals of a linearised least squares, a view at a time: ``(I - H_gg)^-1 r_g`` with ``H`` the hat
    matrix ``J (J^T J)^-1 J^T``); near 1 when the views are many for the parameters, large when each view's own error
    is fitted."""
    rows = np.flatnonzero(kept & (residuals != 0))
    if not len(rows):
        return 1.0
    H_inv = np.linalg.pinv(J.T @ J)
    deleted = []
    for g in np.unique(view_of[rows]):
        idx = rows[view_of[rows] == g]
        Jg = J[idx]
        hat = Jg @ H_inv @ Jg.T
        try:
            deleted.append(np.linalg.solve(np.eye(len(idx)) - hat, residuals[idx]))
        except np.linalg.LinAlgError:  # a view that alone fixes a parameter: its left-out prediction is unbounded
            return float("inf")
    fitted = float(np.sqrt(np.mean(residuals[rows] ** 2)))
    return float(np.sqrt(np.mean(np.concatenate(deleted) ** 2))) / max(fitted, 1e-12)
