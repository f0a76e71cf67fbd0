"""A solve's inputs in the JSON form ``videocal solve`` reads: what a recording keeps of every solve, so that it can
be re-solved and compared (:mod:`calib_core.recording.replay`)."""

from __future__ import annotations

import numpy as np

from calib_core.camera.intrinsics import Intrinsics


def solve_inputs(
    points_3d,
    points_2d,
    intrinsics: Intrinsics,
    *,
    prior=None,
    estimate_focal=False,
    model="pinhole",
    sigma_px=None,
    robust=False,
) -> dict:
    """The JSON form of a solve's inputs (the fields of ``videocal solve``)."""
    inputs = {
        "intrinsics": intrinsics.to_dict(),
        "points_3d": np.asarray(points_3d, dtype=float).tolist(),
        "points_2d": np.asarray(points_2d, dtype=float).tolist(),
        "estimate_focal": bool(estimate_focal),
        "model": model,
        "sigma_px": sigma_px,
        "robust": bool(robust),
    }
    if prior is not None:
        inputs["prior"] = {
            "R_obj2cam": np.asarray(prior)[:3, :3].tolist(),
            "t_obj2cam_mm": np.asarray(prior)[:3, 3].tolist(),
        }
    return inputs
