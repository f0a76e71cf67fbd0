"""The pose solver's speed beside OpenCV and PoseLib on the same problems in the same run: a section of
``docs/benchmarks/solver.md`` (bench/solver_bench.py)."""

from __future__ import annotations

import time

import numpy as np

from bench.solver_scenes import CAM, NOISE_PX, _displaced, _opencv, _scene, _time_per_call
from calib_core.solver import solve_pose, solve_pose_batch
from calib_core.solver.fast_solve import Tie
from calib_core.solver.sampler import INLIER_SIGMAS

SPEED_SCENES = 300


PASSES = 5


def _mean_per_solve(fns, problems) -> list[float]:
    """Each of ``fns``' mean time (s) of ``fn(P, uv)`` over ``problems``, the best of :data:`PASSES` passes (each pass
    every problem once); the solvers' passes take turns, so that a machine busier for a while slows each alike."""
    best = [np.inf] * len(fns)
    for _ in range(PASSES):
        for k, fn in enumerate(fns):
            t0 = time.perf_counter()
            for P, uv in problems:
                fn(P, uv)
            best[k] = min(best[k], (time.perf_counter() - t0) / len(problems))
    return best


def _poselib_plain(P, uv):
    import poselib

    camera = {"model": "PINHOLE", "width": CAM.width, "height": CAM.height, "params": [CAM.fu, CAM.fv, CAM.cx, CAM.cy]}
    return poselib.estimate_absolute_pose(
        uv, P, camera, {"max_reproj_error": INLIER_SIGMAS * NOISE_PX, "min_iterations": 0}, {}
    )


def speed_section(rng) -> list[str]:
    lines = [
        f"## Speed ({SPEED_SCENES} different scenes a row at {NOISE_PX} px noise, no prior; mean per solve, best of "
        f"{PASSES} passes taken in turn; a whole solve: "
        "checks, seeds, refinement, covariance, leave-one-out and the mis-pick test)",
        "",
        "Every solver sees the same problems after a warm-up (videocal's compiled kernels loaded, the full search run "
        "once). PoseLib runs "
        "`estimate_absolute_pose` (P3P/LO-RANSAC and its bundle adjustment) with `min_iterations` 0, so that a clean "
        "set ends after its first "
        "hypotheses: its fastest use for a plain solve. `full search` counts videocal's solves that left the compiled "
        "fast path; `ties` those where the fast path found two poses fitting about as well (a plane's mirror pose) and "
        "handed them to the full search's ranking (reported `ambiguous`, as the full search reports them).",
        "",
        "| problem | videocal solve_pose | full search | ties | OpenCV SQPnP + RefineLM | PoseLib | videocal / OpenCV "
        "(target <= 1.0) | videocal / PoseLib (target <= 2.0) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    import calib_core.solver.solve as solve_module

    for n, planar in ((4, False), (5, False), (6, False), (8, False), (20, False), (4, True)):
        problems = [
            (P, uv + rng.normal(0, NOISE_PX, uv.shape))
            for _, P, uv in (_scene(rng, n, planar) for _ in range(SPEED_SCENES))
        ]
        peer = "ippe+lm" if planar else "sqpnp+lm"
        slow, ties = [], []
        fast = solve_module.fast_solve

        def counted(*a, **k):
            out = fast(*a, **k)
            (slow if out is None else ties if isinstance(out, Tie) else []).append(1)
            return out

        solve_module.fast_solve = counted
        try:
            for P, uv in problems:
                solve_pose(P, uv, CAM)
        finally:
            solve_module.fast_solve = fast
        for P, uv in problems[:10]:  # warm-up
            _opencv(peer, P, uv)
            _poselib_plain(P, uv)
        ours, cv, pl = _mean_per_solve(
            [lambda P, uv: solve_pose(P, uv, CAM), lambda P, uv: _opencv(peer, P, uv), _poselib_plain], problems
        )
        lines.append(
            f"| N = {n}{' on a plane (OpenCV: IPPE + RefineLM)' if planar else ''} | {ours * 1e6:.0f} us "
            f"| {len(slow)} of {SPEED_SCENES} | {len(ties)} | {cv * 1e6:.0f} us | {pl * 1e6:.0f} us "
            f"| {ours / cv:.2f} | {ours / pl:.2f} |"
        )
    scenes = [_scene(rng, 6) for _ in range(1000)]
    P = np.stack([s[1] for s in scenes])
    uv = np.stack([s[2] + rng.normal(0, NOISE_PX, (6, 2)) for s in scenes])
    starts = np.stack([_displaced(rng, s[0], 20, 5) for s in scenes])
    batch_seeded = _time_per_call(lambda: solve_pose_batch(P, uv, CAM, starts=starts), 1) / 1000
    batch_free = _time_per_call(lambda: solve_pose_batch(P, uv, CAM), 1) / 1000
    cv_loop = _time_per_call(lambda: [_opencv("sqpnp+lm", P[i], uv[i]) for i in range(1000)], 1) / 1000
    lines += [
        "",
        "| batch of 1000 problems, N = 6 | per problem | target |",
        "|---|---|---|",
        f"| solve_pose_batch from starts (20 mm / 5 deg off) | {batch_seeded * 1e6:.1f} us | <= 20 us |",
        f"| solve_pose_batch without starts (batched DLT seeds) | {batch_free * 1e6:.1f} us | |",
        f"| OpenCV SQPnP + RefineLM in a Python loop | {cv_loop * 1e6:.1f} us | |",
        "",
    ]
    return lines
