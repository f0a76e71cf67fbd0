"""numba's cache of the solver's kernels lives in a folder named by their sources: a change to any kernel (a callee in
another file included, which numba's own check misses) is compiled afresh, never served from an older version's
cache; a folder the user names (NUMBA_CACHE_DIR) is kept."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
PROBE = "import calib_core.solver.kernels.newton\nfrom numba.core import config\nprint(config.CACHE_DIR)\n"


def _without_a_chosen_folder() -> dict[str, str]:
    # The suite names the user's folder for every process it starts (tests/conftest.py); these tests see the choice
    # the program makes when nobody has chosen.
    return {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}


def _cache_folder(source_root: Path, cache_home: Path, **env) -> Path:
    run = subprocess.run(
        [sys.executable, "-c", PROBE],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=source_root,
        env={**_without_a_chosen_folder(), "PYTHONPATH": str(source_root), "XDG_CACHE_HOME": str(cache_home), **env},
    )
    assert run.returncode == 0, run.stderr[-2000:]
    return Path(run.stdout.strip())


def test_a_changed_kernel_gets_a_cache_folder_of_its_own(tmp_path):
    copy = tmp_path / "src"
    shutil.copytree(ROOT / "calib_core", copy / "calib_core", ignore=shutil.ignore_patterns("__pycache__"))
    cache_home = tmp_path / "cache"
    first = _cache_folder(copy, cache_home)
    assert first.parent == cache_home / "videocal" / "numba" and first.is_dir()
    assert _cache_folder(copy, cache_home) == first  # the same sources, the same folder
    newton = copy / "calib_core" / "solver" / "kernels" / "newton.py"
    newton.write_text(newton.read_text() + "\n# a change to the Newton loop, which other kernels call\n")
    changed = _cache_folder(copy, cache_home)
    assert changed != first and changed.parent == first.parent


def test_a_cache_folder_the_user_names_is_kept(tmp_path):
    chosen = tmp_path / "chosen"
    chosen.mkdir()
    assert _cache_folder(ROOT, tmp_path / "cache", NUMBA_CACHE_DIR=str(chosen)) == chosen
