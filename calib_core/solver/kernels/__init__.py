"""Compiled (numba) inner loops of the pose solver: camera models and the damped Newton loop.

The solver's arithmetic on a handful of points is dominated by interpreter overhead in
numpy (about 1 us per call on arrays of six points); compiled scalar loops make a whole
single solve cheaper than OpenCV's own refinement, and the batch form runs them on every core.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path


def _cache_dir_of_these_sources() -> str | None:
    """A folder for numba's cache named by these kernels' sources, or None where none can be made.

    numba keeps a compiled function until its own file changes, not a function it calls from another file: after
    ``newton.py`` changed, ``subset_fit``'s cached code still ran the old Newton loop (a benchmark measured code that
    was gone). A folder per version of the sources makes every change a fresh compile."""
    here = Path(__file__).resolve().parent
    digest = hashlib.sha1()
    for source in sorted(here.glob("*.py")):
        digest.update(source.name.encode() + b"\0" + source.read_bytes())
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "videocal" / "numba"
    folder = root / digest.hexdigest()[:16]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return str(folder) if os.access(folder, os.W_OK) else None


def _use_a_cache_per_version() -> None:
    # numba reads the folder when each cached kernel is defined: set before any module here is imported. A folder the
    # user chose (NUMBA_CACHE_DIR) is kept.
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    folder = _cache_dir_of_these_sources()
    if folder is not None:
        from numba.core import config

        config.CACHE_DIR = folder


_use_a_cache_per_version()
