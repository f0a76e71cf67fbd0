"""The focal lengths solved with the pose, beside PoseLib's minimal P4Pf on the same scenes: a section of
``docs/benchmarks/solver.md`` (bench/solver_bench.py)."""

from __future__ import annotations

import itertools

import numpy as np
import poselib

from bench.solver_scenes import CAM, NOISE_PX, _scene
from calib_core.camera.intrinsics import Intrinsics
from calib_core.solver import solve_pose

FOCAL_SCENES = 400
GIVEN_OFF = 0.10
"""The focal lengths videocal is given to start from: this far off the truth (either way)."""
GROSS = 0.30
"""A focal length further off than this (relative), or none, is a gross failure."""


def _p4pf_best_subset(P, uv) -> float | None:
    """PoseLib's P4Pf on every four of the pairs, the focal length (px) of the root that fits all of them best."""
    x = uv - np.array([CAM.cx, CAM.cy])
    best_cost, best_f = np.inf, None
    for subset in itertools.combinations(range(len(P)), 4):
        rows = list(subset)
        poses, focals = poselib.p4pf(x[rows], P[rows], True)
        for pose, f in zip(poses, focals):
            X = P @ np.asarray(pose.R).T + np.asarray(pose.t)
            if np.any(X[:, 2] <= 0.0):
                continue
            cost = float(np.sum((f * X[:, :2] / X[:, 2:] - x) ** 2))
            if cost < best_cost:
                best_cost, best_f = cost, float(f)
    return best_f


def _summary(errors: np.ndarray) -> str:
    found = np.isfinite(errors)
    gross = found & (np.abs(errors) > GROSS)
    good = found & ~gross
    rms = 100.0 * np.sqrt(np.mean(errors[good] ** 2)) if good.any() else np.nan
    return f"{rms:.1f} % | {100.0 * (gross.sum() + (~found).sum()) / len(errors):.1f} %"


def focal_section(rng) -> list[str]:
    lines = [
        f"## Unknown focal lengths ({FOCAL_SCENES} scenes a row at {NOISE_PX} px noise)",
        "",
        f"videocal's `solve_pose(estimate_focal=True)`, given focal lengths {100 * GIVEN_OFF:.0f} % off the truth, "
        "against PoseLib's minimal P4Pf on every four of the pairs, the root that fits all the pairs best. videocal "
        "solves fu and fv apart (8 unknowns: four pairs fit exactly), P4Pf one focal length for square pixels (7). "
        f"RMS of the focal length's relative error over the answers within {100 * GROSS:.0f} %; gross: further off, or "
        "no answer (videocal: `failed`).",
        "",
        "| points | videocal RMS | videocal gross | PoseLib P4Pf RMS | PoseLib P4Pf gross |",
        "|---|---|---|---|---|",
    ]
    truth = np.sqrt(CAM.fu * CAM.fv)
    for n in (4, 5, 6, 8):
        ours, theirs = [], []
        for _ in range(FOCAL_SCENES):
            _, P, uv = _scene(rng, n)
            uv = uv + rng.normal(0.0, NOISE_PX, uv.shape)
            given = 1.0 + rng.choice([-1.0, 1.0]) * GIVEN_OFF
            intrinsics = Intrinsics(CAM.fu * given, CAM.fv * given, CAM.cx, CAM.cy, CAM.width, CAM.height)
            solution = solve_pose(P, uv, intrinsics, estimate_focal=True)
            ours.append(np.nan if solution.status.value == "failed" else solution.fu / CAM.fu - 1.0)
            f = _p4pf_best_subset(P, uv)
            theirs.append(np.nan if f is None else f / truth - 1.0)
        lines.append(f"| {n} | {_summary(np.array(ours))} | {_summary(np.array(theirs))} |")
    return lines + [""]
