"""The bench's peers in environments of their own: a venv beside the project's (``.venv-peers``) with OpenCV contrib's
Python wheel, whose ``cv2`` cannot live beside videocal's ``opencv-python-headless``, and ViSP's model-based tracker
built there from a small C++ program against the system's ViSP. Made by the bench when first asked (pip, from PyPI;
g++), never by the tests; what it cannot make is said, and the bench's rows for it say so."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PEERS = ROOT / ".venv-peers"
OPENCV_CONTRIB = "opencv-contrib-python-headless==4.14.0.94"
"""The release of videocal's own OpenCV (5.1.0.95's OLS and GOS trackers fail an assertion from Python)."""


def peer_python() -> tuple[Path | None, str]:
    """The peers' Python (made if missing) and what it holds, or None and why not."""
    python = PEERS / "bin" / "python"
    if not python.exists():
        made = subprocess.run([sys.executable, "-m", "venv", str(PEERS)], capture_output=True, text=True)
        if made.returncode != 0:
            return None, f"could not make {PEERS}: {made.stderr.strip()[-200:]}"
    wanted = OPENCV_CONTRIB.split("==")[1].rsplit(".", 1)[0]  # 4.14.0.94 -> cv2.__version__ 4.14.0
    check = subprocess.run(
        [str(python), "-c", "import cv2; print(cv2.__version__, hasattr(cv2, 'rapid'))"], capture_output=True, text=True
    )
    if check.returncode != 0 or check.stdout.split() != [wanted, "True"]:
        got = subprocess.run(
            [str(python), "-m", "pip", "install", "--quiet", OPENCV_CONTRIB, "numpy"],
            capture_output=True,
            text=True,
            timeout=900,
        )
        if got.returncode != 0:
            return None, f"pip could not install {OPENCV_CONTRIB}: {' '.join(got.stderr.split())[-300:]}"
        check = subprocess.run(
            [str(python), "-c", "import cv2; print(cv2.__version__, hasattr(cv2, 'rapid'))"],
            capture_output=True,
            text=True,
        )
    return python, f"OpenCV contrib {check.stdout.split()[0]} (cv2.rapid)"


VISP_SOURCE = Path(__file__).resolve().parent / "peers" / "visp_tracker.cpp"
VISP_LIBRARIES = ("visp_mbt", "visp_klt", "visp_me", "visp_vision", "visp_visual_features", "visp_io", "visp_core")
VISP_PACKAGES = "libvisp-mbt-dev nlohmann-json3-dev g++"
"""What the ViSP peer is built from: Debian's ViSP 3.5 (its model-based tracker's headers and libraries), nlohmann's
JSON for the request, a C++ compiler."""


def visp_tracker() -> tuple[Path | None, str]:
    """The ViSP peer's program (``bench/peers/visp_tracker.cpp`` built beside the peers' Python, again when its source
    is newer), or None and why not (the command that installs what it needs)."""
    import shutil

    program = PEERS / "bin" / "visp_tracker"
    if program.exists() and program.stat().st_mtime >= VISP_SOURCE.stat().st_mtime:
        return program, _visp_version()
    compiler = shutil.which("g++")
    if compiler is None:
        return None, f"no C++ compiler (apt-get install {VISP_PACKAGES})"
    program.parent.mkdir(parents=True, exist_ok=True)
    built = subprocess.run(
        [compiler, "-O2", "-std=c++17", "-I/usr/include/opencv4", str(VISP_SOURCE), "-o", str(program)]
        + [f"-l{name}" for name in VISP_LIBRARIES],
        capture_output=True,
        text=True,
        timeout=600,
    )
    if built.returncode != 0:
        return None, f"could not build the ViSP peer (apt-get install {VISP_PACKAGES}): {built.stderr.strip()[-200:]}"
    return program, _visp_version()


def _visp_version() -> str:
    try:
        found = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "libvisp-mbt-dev"], capture_output=True, text=True)
        version = found.stdout.strip()
    except OSError:  # not a Debian system
        version = ""
    return f"ViSP {version or '(version unknown)'} (vpMbEdgeTracker, vpMbEdgeKltTracker)"
