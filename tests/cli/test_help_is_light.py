"""A command's --help loads nothing heavy: no solver kernels (numba), no scipy, no mesh or image library, no VTK, no
Qt. (The solver's, the locator's and the renderer's --help each took about a second of CPU importing them.)"""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("numba", "scipy", "trimesh", "cv2", "vtkmodules", "pinocchio", "PySide6")
PROBE = (
    "import atexit, sys\n"
    "atexit.register(lambda: print('LOADED', *[m for m in %r if m in sys.modules], file=sys.stderr))\n"
    "from app.cli.main import main\n"
    "sys.argv = ['videocal', %r, '--help']\n"
    "main()\n"
)


@pytest.mark.parametrize(
    "command",
    [
        "solve",
        "export",
        "locate",
        "render",
        "table1",
        "gui",
        "monitor",
        "grab",
        "new-cell",
        "calibrate-intrinsics",
        "calibrate-hand-eye",
        "calibrate-robot",
        "replay",
        "recover",
        "link-key",
        "demo",
    ],
)
def test_help_loads_nothing_heavy(command):
    run = subprocess.run(
        [sys.executable, "-c", PROBE % (HEAVY, command)], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert run.returncode == 0 and "usage: videocal" in run.stdout, run.stderr[-2000:]
    loaded = next(line for line in run.stderr.splitlines() if line.startswith("LOADED")).split()[1:]
    assert loaded == [], f"videocal {command} --help loads {', '.join(loaded)}"
