"""Compile the solver's numba kernels once, into numba's on-disk cache, so the operator's first solve
does not wait for them.

Each kernel compiles on its first call with a new type signature and is cached for every later process, in a
folder named by the kernels' sources (``~/.cache/videocal/numba/<hash>``, :mod:`calib_core.solver.kernels`). On a
fresh install that first call is the operator's first Calibrate: the window froze for 2-9 s on a 2-core machine
(four pairs take one compiled path, six another, a robust solve a third). ``make venv`` runs this after
installing; ``python -m calib_core.solver.compile_kernels`` does it by hand and prints how long it took.
"""

from __future__ import annotations

import time

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.solver import solve_pose
from calib_core.solver.batch import solve_pose_batch


def _scene(n: int, rng: np.random.Generator, planar: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points (n, 3) mm of a 150 mm object and the (4, 4) pose that puts it 500 mm in front."""
    points = rng.uniform(-75.0, 75.0, (n, 3))
    if planar:
        points[:, 2] = 0.0
    obj2cam = np.eye(4)
    obj2cam[:3, 3] = (10.0, -5.0, 500.0)
    return points, obj2cam


def compile_kernels() -> float:
    """Run one solve down each compiled path (pinhole and distorted, four to six pairs, coplanar,
    focal lengths estimated, robust with and without a prior, a batch); returns the seconds it took. Each kernel
    called from Python is called here with every argument type a look gives it (an array's order is part of
    it), so that a look compiles nothing: a test runs a first look after this and finds no new signature."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(0)
    pinhole = Intrinsics(1100.0, 1100.0, 640.0, 480.0, 1280, 960)
    distorted = Intrinsics(1100.0, 1100.0, 640.0, 480.0, 1280, 960, distortion=(-0.1, 0.05, 0.0, 0.0, 0.0))
    for n, planar in ((4, False), (5, False), (6, False), (12, False), (4, True), (8, True)):
        points, obj2cam = _scene(n, rng, planar)
        uv = project_points(points, obj2cam, pinhole) + rng.normal(0.0, 0.2, (n, 2))
        solve_pose(points, uv, pinhole, sigma_px=0.5)
        solve_pose(points, uv, distorted, sigma_px=0.5)
        solve_pose(points, uv, pinhole, prior=obj2cam, sigma_px=0.5)
        if n >= 6:
            solve_pose(points, uv, pinhole, estimate_focal=True)
    points, obj2cam = _scene(40, rng)
    uv = project_points(points, obj2cam, pinhole) + rng.normal(0.0, 0.3, (40, 2))
    uv[:8] = rng.uniform(0.0, 900.0, (8, 2))
    solve_pose(points, uv, pinhole, robust=True, sigma_px=0.5)
    # Find points' fit: robust from the model's pose (its residuals from Python, before any consensus)
    solve_pose(points, uv, pinhole, robust=True, prior=obj2cam, sigma_px=0.5)
    scenes = [_scene(6, rng) for _ in range(4)]
    solve_pose_batch(
        np.array([p for p, _ in scenes]), np.array([project_points(p, T, pinhole) for p, T in scenes]), pinhole
    )
    return time.perf_counter() - t0


def called_signatures() -> set[tuple[str, str, str]]:
    """Every signature the process holds of the solver's kernels, as (module, kernel, signature): those compiled or
    loaded from numba's cache by a call from Python, and the callees a fresh compile made. A call that adds one
    compiled it, or loaded it from the cache where this module's run had not (0.2-1.7 s a path on two cores)."""
    import importlib
    import pkgutil

    from numba.core.registry import CPUDispatcher

    import calib_core.solver.kernels as kernels

    held = set()
    for info in pkgutil.iter_modules(kernels.__path__):
        module = importlib.import_module(f"{kernels.__name__}.{info.name}")
        for name, value in vars(module).items():
            if isinstance(value, CPUDispatcher) and value.__module__ == module.__name__:
                held |= {(info.name, name, str(signature)) for signature in value.signatures}
    return held


if __name__ == "__main__":
    print(f"the solver's kernels compiled (or found in numba's cache) in {compile_kernels():.1f} s")
