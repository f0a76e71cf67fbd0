"""How often a robust solve is wrong but called ``ok``, and how often a mis-pick is caught, against
PoseLib and OpenCV on the same scenes. Sections of ``docs/benchmarks/solver.md`` (bench/solver_bench.py).

A pose is *right* when its translation is within 5 sigma + 0.5 mm of the truth, sigma being the translation
1-sigma (norm) of the least-squares pose on the good pairs alone with the noise known: what the pairs allow.
videocal's answer counts as *wrong ok* when its status is ``ok`` and the pose is not right; the peers have no
status, so every pose they return counts as their answer.
"""

from __future__ import annotations

import numpy as np

from calib_core.camera.projection import project_points
from calib_core.frames import make_transform
from calib_core.solver import solve_pose
from scipy.spatial.transform import Rotation

from bench.solver_robust import _opencv_ransac, _poselib
from bench.solver_scenes import CAM, NOISE_PX

SCENES = 200


def _scene(rng: np.random.Generator, n: int):
    R = Rotation.from_rotvec(rng.normal(0.0, 0.35, 3)).as_matrix()
    T = make_transform(R, np.array([rng.uniform(-60, 60), rng.uniform(-50, 50), 500.0 * rng.uniform(0.8, 1.2)]))
    P = rng.uniform(-75, 75, (n, 3))
    return T, P, project_points(P, T, CAM) + rng.normal(0.0, NOISE_PX, (n, 2))


def _right(pose, T, allowed_mm: float) -> bool:
    return (
        pose is not None
        and bool(np.all(np.isfinite(pose)))
        and float(np.linalg.norm(pose[:3, 3] - T[:3, 3])) <= allowed_mm
    )


def _peers(P, uv):
    """OpenCV's RANSAC and PoseLib's LO-RANSAC, as the robust timing rows call them; a peer that raises gives None."""
    try:
        theirs = _poselib(P, uv)
    except (RuntimeError, ValueError):
        theirs = None
    return _opencv_ransac(P, uv), theirs


def robust_reliability_section(rng: np.random.Generator) -> list[str]:
    lines = [
        "## Robust solves: wrong `ok` and success (outliers uniform over the image, 0.5 px noise, the noise model's "
        "default)",
        "",
        f"{SCENES} scenes per row; the outliers are round(share x N) pairs (at least one). `right` = within 5 sigma + "
        "0.5 mm of the truth "
        "(sigma: the least-squares pose of the good pairs with the noise known). videocal's `wrong ok` is an `ok` "
        "whose pose is not right "
        "(target 0); its success is an `ok` that is right; the peers return a pose or nothing, so their `wrong` is any "
        "pose returned that is "
        "not right. With 5 pairs and 2 outliers only 3 good pairs are left: no pose can be checked, the right answer "
        "is `failed`.",
        "",
        "| N | outliers | videocal wrong ok | videocal ok and right | ambiguous / failed | OpenCV RANSAC wrong / right "
        "| PoseLib wrong / right |",
        "|---|---|---|---|---|---|---|",
    ]
    for n in (5, 6, 8, 10, 20):
        for share in (0.1, 0.2, 0.3, 0.4):
            k = max(1, round(share * n))
            counts = dict(wrong=0, right=0, unsure=0, cv_wrong=0, cv_right=0, pl_wrong=0, pl_right=0)
            for _ in range(SCENES):
                T, P, uv = _scene(rng, n)
                bad = rng.choice(n, k, replace=False)
                good = np.setdiff1d(np.arange(n), bad)
                oracle = solve_pose(P[good], uv[good], CAM, sigma_px=NOISE_PX) if len(good) >= 4 else None
                allowed = 0.5 + 5.0 * (
                    np.linalg.norm(oracle.uncertainty.std_t_obj2cam_mm)
                    if oracle is not None and oracle.uncertainty
                    else 0.0
                )
                uv[bad] = rng.uniform([0, 0], [CAM.width, CAM.height], (k, 2))
                s = solve_pose(P, uv, CAM, robust=True)
                if s.status.value == "ok":
                    counts["right" if _right(s.obj2cam, T, allowed) else "wrong"] += 1
                else:
                    counts["unsure"] += 1
                for name, pose in zip(("cv", "pl"), _peers(P, uv)):
                    if pose is not None:
                        counts[f"{name}_{'right' if _right(pose, T, allowed) else 'wrong'}"] += 1
            pct = {key: 100.0 * v / SCENES for key, v in counts.items()}
            lines.append(
                f"| {n} | {k} ({share:.0%}) | {counts['wrong']} | {pct['right']:.0f} % | {pct['unsure']:.0f} % | "
                f"{pct['cv_wrong']:.0f} % / {pct['cv_right']:.0f} % | {pct['pl_wrong']:.0f} % / {pct['pl_right']:.0f} "
                "% |"
            )
    return lines + [""]


def mis_pick_section(rng: np.random.Generator) -> list[str]:
    lines = [
        "## Mis-picks caught (one pick moved by the stated distance among N good ones at 0.5 px)",
        "",
        f"{SCENES} scenes per cell. Plain: the solve is not `ok` and names that pair (its misfit test); robust: that "
        "pair is rejected "
        "(and no good one). The clean column is the share of clean sets where a good pair is named (false flags).",
        "",
        "| N | mode | clean: false flags | 5 px | 10 px | 20 px |",
        "|---|---|---|---|---|---|",
    ]
    for n in (6, 10, 20):
        for robust in (False, True):
            cells = []
            for off in (0.0, 5.0, 10.0, 20.0):
                caught = 0
                for _ in range(SCENES):
                    T, P, uv = _scene(rng, n)
                    bad = int(rng.integers(n))
                    d = rng.normal(size=2)
                    uv[bad] += d / np.linalg.norm(d) * off
                    s = solve_pose(P, uv, CAM, robust=robust)
                    flags = s.outliers if robust else (s.misfits if s.misfits is not None else np.zeros(n, dtype=bool))
                    if off == 0.0:
                        caught += bool(flags.any())
                    else:
                        caught += bool(flags[bad]) and int(flags.sum()) == 1 and (robust or s.status.value != "ok")
                cells.append(f"{100.0 * caught / SCENES:.1f} %")
            lines.append(f"| {n} | {'robust' if robust else 'plain'} | " + " | ".join(cells) + " |")
    return lines + [""]
