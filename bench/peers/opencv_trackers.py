"""OpenCV contrib's model-based trackers (``cv2.rapid``: RAPID's edges, OLS and GOS's colour-region searches) on one
view, as the real-photo bench's peer. Runs in its own environment (``bench/peer_env.py``:
opencv-contrib-python-headless,
which cannot share a Python environment with videocal's opencv-python-headless), so it imports nothing of videocal.

Reads JSON on stdin: ``{"image": PNG path, "K": 3x3, "vertices": (n, 3) mm, "faces": (m, 3), "views": [{"rvec", "tvec"}]
(the priors), "iterations": n}``; writes one line of JSON: per tracker, per prior, the pose it ends at and its seconds.
"""

from __future__ import annotations

import json
import sys
import time

import cv2
import numpy as np

TRACKERS = {
    "rapid": lambda pts, tris: cv2.rapid.Rapid.create(pts, tris),
    "ols": lambda pts, tris: cv2.rapid.OLSTracker.create(pts, tris),
    "gos": lambda pts, tris: cv2.rapid.GOSTracker.create(pts, tris),
}


def main() -> int:
    request = json.loads(sys.stdin.read())
    image = cv2.imread(request["image"], cv2.IMREAD_COLOR)
    K = np.asarray(request["K"], dtype=np.float64)
    pts = np.asarray(request["vertices"], dtype=np.float32)
    tris = np.asarray(request["faces"], dtype=np.int32)
    out = {}
    for name, make in TRACKERS.items():
        rows = []
        for view in request["views"]:
            tracker = make(pts, tris)
            rvec = np.asarray(view["rvec"], dtype=np.float64).reshape(3, 1)
            tvec = np.asarray(view["tvec"], dtype=np.float64).reshape(3, 1)
            t0 = time.perf_counter()
            ratio = 0.0
            try:
                for _ in range(int(request.get("iterations", 10))):
                    if name == "rapid":
                        ratio, rvec, tvec = tracker.compute(image, 200, 15, K, rvec, tvec)
                    else:
                        ratio, rvec, tvec = tracker.compute(
                            image, 200, 15, K, rvec, tvec, (cv2.TERM_CRITERIA_MAX_ITER, 3, 0)
                        )
                ok = bool(np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec)))
            except cv2.error as exc:
                ok, ratio = False, str(exc).strip().splitlines()[-1]
            rows.append(
                {
                    "ok": ok,
                    "rvec": np.asarray(rvec).ravel().tolist(),
                    "tvec": np.asarray(tvec).ravel().tolist(),
                    "ratio": float(ratio) if isinstance(ratio, (int, float)) else ratio,
                    "seconds": time.perf_counter() - t0,
                }
            )
        out[name] = rows
    sys.stdout.write(json.dumps(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
