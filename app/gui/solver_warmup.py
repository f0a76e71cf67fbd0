"""The solver's compiled kernels loaded behind the window, so the operator's first Calibrate is as quick
as the rest (loading them from numba's cache on first use took 0.2-1.7 s a path on a 2-core machine:
the first solves of a session missed the 100 ms target by that)."""

from __future__ import annotations

import threading


def warm_solver_in_background() -> threading.Thread:
    """Start (and return) a daemon thread that runs one solve down each compiled path. Numba's
    dispatchers lock their own compilation, so a solve the operator starts meanwhile is safe: it waits
    for the kernel it needs at most."""
    from calib_core.solver.compile_kernels import compile_kernels

    thread = threading.Thread(target=compile_kernels, name="videocal-solver-warm-up", daemon=True)
    thread.start()
    return thread
