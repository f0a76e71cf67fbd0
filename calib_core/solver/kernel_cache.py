"""Where numba keeps the solver's compiled kernels: a folder named by their sources.

numba keeps a compiled function until its own file changes, not a function it calls from another file: after
``newton.py`` changed, ``subset_fit``'s cached code still ran the old Newton loop (a benchmark measured code that was
gone). A folder per version of the sources makes every change a fresh compile. This module imports no numba, so a
launcher (the test suite's set-up) can name the folder before anything compiles.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

KERNELS = Path(__file__).resolve().parent / "kernels"


def kernel_cache_folder() -> str | None:
    """The folder (``$XDG_CACHE_HOME/videocal/numba/<hash of the kernels' sources>``) made if missing, or None where
    none can be made or written."""
    digest = hashlib.sha1()
    for source in sorted(KERNELS.glob("*.py")):
        digest.update(source.name.encode() + b"\0" + source.read_bytes())
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "videocal" / "numba"
    folder = root / digest.hexdigest()[:16]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return str(folder) if os.access(folder, os.W_OK) else None
