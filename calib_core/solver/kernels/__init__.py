"""Compiled (numba) inner loops of the pose solver: camera models and the damped Newton loop.

The solver's arithmetic on a handful of points is dominated by interpreter overhead in
numpy (about 1 us per call on arrays of six points); compiled scalar loops make a whole
single solve cheaper than OpenCV's own refinement, and the batch form runs them on every core.
"""

from __future__ import annotations

import os

from calib_core.solver.kernel_cache import kernel_cache_folder


def _use_a_cache_per_version() -> None:
    # numba reads the folder when each cached kernel is defined: set before any module here is imported. A folder the
    # user chose (NUMBA_CACHE_DIR) is kept.
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    folder = kernel_cache_folder()
    if folder is not None:
        from numba.core import config

        config.CACHE_DIR = folder


_use_a_cache_per_version()
