"""What the operator's first Calibrate and first Find points need, made behind the window so they are as quick as
the rest: the solver's compiled kernels (loading them from numba's cache on first use took 0.2-1.7 s a path on a
2-core machine: the first solves of a session missed the 100 ms target by that) and the camera's lens map (every
pixel undistorted, 0.6 s at 1280 x 960: the first Find points of a session took 2.2 s with a core busy, the second
0.8 s)."""

from __future__ import annotations

import threading

from calib_core.camera.intrinsics import Intrinsics


def warm_up_in_background(intrinsics: Intrinsics | None = None) -> threading.Thread:
    """Start (and return) a daemon thread that runs one solve down each compiled path, then makes the lens map of
    ``intrinsics`` (kept by :func:`calib_core.camera.distortion_map.distortion_map`). Numba's dispatchers lock their
    own compilation, so a solve the operator starts meanwhile is safe: it waits for the kernel it needs at most; a
    Find points meanwhile makes the map itself."""

    def warm() -> None:
        from calib_core.solver.compile_kernels import compile_kernels

        compile_kernels()
        if intrinsics is not None:
            from calib_core.camera.distortion_map import distortion_map

            distortion_map(intrinsics)

    thread = threading.Thread(target=warm, name="videocal-warm-up", daemon=True)
    thread.start()
    return thread
