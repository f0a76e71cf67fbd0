"""The solver bench's robust rows: videocal's robust mode beside OpenCV's solvePnPRansac and PoseLib on generated
scenes with outliers and on OpenCV's tutorial's real pairs (time, success, memory). A section of
``docs/benchmarks/solver.md`` (bench/solver_bench.py writes it)."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import cv2
import numpy as np
import poselib

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from calib_core.solver import solve_pose
from calib_core.solver.sampler import INLIER_SIGMAS
from bench.solver_scenes import CAM, NOISE_PX, _cv_pose, _errors, _scene, _time_per_call


def _with_outliers(rng, n, share):
    T, P, uv = _scene(rng, n)
    noisy = uv + rng.normal(0, NOISE_PX, uv.shape)
    bad = rng.random(n) < share
    noisy[bad] = rng.uniform([0, 0], [CAM.width, CAM.height], (int(bad.sum()), 2))
    return T, P, noisy, bad


def _opencv_ransac(P, uv, cam=CAM, noise_px=NOISE_PX):
    """OpenCV's solvePnPRansac as its documentation shows it, with the same inlier threshold as videocal."""
    Kc = np.array([[cam.fu, 0.0, cam.cx], [0.0, cam.fv, cam.cy], [0.0, 0.0, 1.0]])
    ok, rvec, tvec, _ = cv2.solvePnPRansac(
        P,
        uv,
        Kc,
        None,
        reprojectionError=INLIER_SIGMAS * noise_px,
        confidence=0.9999,
        iterationsCount=10000,
        flags=cv2.SOLVEPNP_AP3P,
    )
    return _cv_pose(rvec, tvec) if ok else None


def _poselib(P, uv, cam=CAM, noise_px=NOISE_PX):
    camera = {"model": "PINHOLE", "width": cam.width, "height": cam.height, "params": [cam.fu, cam.fv, cam.cx, cam.cy]}
    pose, _ = poselib.estimate_absolute_pose(uv, P, camera, {"max_reproj_error": INLIER_SIGMAS * noise_px}, {})
    return make_transform(np.asarray(pose.R), np.asarray(pose.t))


TUTORIAL_PAIRS = (
    Path(__file__).resolve().parent.parent
    / "tests"
    / "data"
    / "third_party"
    / "opencv_samples"
    / "cookies_ORB_pairs.yml"
)
TUTORIAL_CAM = Intrinsics(718 * 45 / 22.3, 480 * 45 / 14.9, 359.0, 240.0, 718, 480)
TUTORIAL_NOISE_PX = 0.15  # the pairs' own RMS about their least-squares pose


def _robust_row(label: str, cases, cam, noise_px: float, tol: float, reps: int, timed: int) -> str:
    """One row of the robust table: ``cases`` (truth obj2cam, P, uv), the first ``timed`` of them timed (each method's
    median over them); ``ok`` within ``tol`` (the points' unit) and 0.5 deg of the truth."""
    times = np.array(
        [
            [
                _time_per_call(lambda: solve_pose(P, uv, cam, robust=True, sigma_px=noise_px), reps),
                _time_per_call(lambda: _opencv_ransac(P, uv, cam, noise_px), reps),
                _time_per_call(lambda: _poselib(P, uv, cam, noise_px), reps),
            ]
            for _, P, uv in cases[:timed]
        ]
    )
    ours, cv, pl = np.median(times, axis=0)
    _, P, uv = cases[0]
    ok = [0, 0, 0]
    for T, Pk, uvk in cases:
        poses = (
            solve_pose(Pk, uvk, cam, robust=True, sigma_px=noise_px).obj2cam,
            _opencv_ransac(Pk, uvk, cam, noise_px),
            _poselib(Pk, uvk, cam, noise_px),
        )
        for k, pose in enumerate(poses):
            if pose is not None and np.all(np.isfinite(pose)):
                dt, dr = _errors(pose, T)
                ok[k] += dt < tol and dr < 0.5
    tracemalloc.start()
    solve_pose(P, uv, cam, robust=True, sigma_px=noise_px)
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    share_ok = " / ".join(f"{100 * v / len(cases):.0f} %" for v in ok)
    return (
        f"| {label} | {ours * 1e3:.2f} ms | {cv * 1e3:.2f} ms | {pl * 1e3:.2f} ms | {ours / cv:.2f} | {ours / pl:.2f} "
        f"| {share_ok} | {peak:.1f} MB |"
    )


def _tutorial_cases(rng) -> list:
    """OpenCV's real-time pose tutorial's 5914 real pairs (cm), 30 % of the pixels replaced by random
    ones, ten times; the truth is the least-squares pose on all the clean pairs."""
    fs = cv2.FileStorage(str(TUTORIAL_PAIRS), cv2.FILE_STORAGE_READ)
    P = fs.getNode("points_3d").mat().reshape(-1, 3).astype(float)
    uv_clean = fs.getNode("points_2d").mat().reshape(-1, 2).astype(float)
    fs.release()
    reference = solve_pose(P, uv_clean, TUTORIAL_CAM).obj2cam
    cases = []
    for _ in range(10):
        uv = uv_clean.copy()
        wrong = rng.choice(len(P), int(0.3 * len(P)), replace=False)
        uv[wrong] = rng.uniform([0, 0], [TUTORIAL_CAM.width, TUTORIAL_CAM.height], (len(wrong), 2))
        cases.append((reference, P, uv))
    return cases


def robust_section(rng) -> list[str]:
    lines = [
        "## Robust solves (outliers drawn uniformly over the image; the same inlier threshold, 3.72 sigma, for all)",
        "",
        "Time is each method's median over the first scenes (40 of N = 20, 5 of the large ones), each scene's the best "
        "of 5 runs of a whole call; `ok` counts solves within 1 mm and 0.5 deg of the truth over 100 "
        "scenes (10 for the large ones; for the tutorial's pairs, in cm, within 0.05 cm of their least-squares pose); "
        "peak memory is tracemalloc's peak during one call (Python allocations: OpenCV's and PoseLib's own "
        "C++ allocations are not seen). PoseLib runs with its defaults (at least 1000 hypotheses, its own bundle "
        "adjustment).",
        "",
        "| problem | videocal robust | OpenCV solvePnPRansac (AP3P) | PoseLib | videocal / OpenCV (target <= 1.0) | "
        "videocal / PoseLib (target <= 1.0) | ok: videocal / OpenCV / PoseLib | videocal peak memory |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for n, share, reps, timed in ((20, 0.2, 20, 40), (5000, 0.3, 3, 5)):
        cases = [_with_outliers(rng, n, share)[:3] for _ in range(100 if n < 1000 else 10)]
        lines.append(_robust_row(f"N = {n}, {share:.0%} outliers", cases, CAM, NOISE_PX, 1.0, reps, timed))
    lines.append(
        _robust_row(
            "OpenCV tutorial's 5914 real pairs, 30% replaced",
            _tutorial_cases(rng),
            TUTORIAL_CAM,
            TUTORIAL_NOISE_PX,
            0.05,
            3,
            5,
        )
    )
    clean_failures = 0
    for _ in range(200):
        _, P, uv = _scene(rng, 20)
        clean_failures += (
            solve_pose(P, uv + rng.normal(0, NOISE_PX, uv.shape), CAM, robust=True, sigma_px=NOISE_PX).status.value
            != "ok"
        )
    lines += [
        "",
        f"A clean set in robust mode (200 scenes, N = 20, 0.5 px noise): {clean_failures} not `ok` (target 0).",
        "",
    ]
    return lines
