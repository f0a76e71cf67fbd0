"""The bench's peers in environments of their own: a venv beside the project's (``.venv-peers``) with OpenCV contrib's
Python wheel, whose ``cv2`` cannot live beside videocal's ``opencv-python-headless``. Made by the bench when first asked
(pip, from PyPI), never by the tests; what it cannot make is said, and the bench's rows for it say so."""

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
