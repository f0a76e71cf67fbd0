"""The real-photo bench's photograph without ground truth: OpenCV's pose tutorial photo of a printed cookie box, where
agreement between answers from priors far apart is what can be checked (``bench/real_photos.py`` puts it on its
page)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from bench.photo_priors import moved_prior


def box_photo_rows() -> list[str]:
    """OpenCV's photo of a printed cookie box (real, its truth unknown): ``locate`` from seven priors 10-120 mm and
    2 deg off the answer of a prior from six corners picked by hand; each answer's status and how far its seen edges
    lie from that answer (agreement, not accuracy)."""
    import cv2

    from calib_core.camera.intrinsics import Intrinsics
    from calib_core.mesh_files import load_mesh
    from calib_core.look.locate import locate
    from calib_core.look.locate_verdict import image_distance_px

    data = Path(__file__).resolve().parent.parent / "tests" / "data" / "third_party" / "opencv_samples"
    image = np.ascontiguousarray(cv2.imread(str(data / "resized_IMG_3875.JPG"))[:, :, ::-1])
    mesh = load_mesh(data / "box.ply", units="cm")
    camera = Intrinsics(718 * 45 / 22.3, 480 * 45 / 14.9, 359.0, 240.0, 718, 480)  # the tutorial's nominal lens
    hand = np.eye(4)
    u, _, vt = np.linalg.svd(
        np.array([[0.7512, -0.6587, -0.0433], [-0.3824, -0.3808, -0.8419], [0.538, 0.649, -0.5379]])
    )
    hand[:3, :3], hand[:3, 3] = u @ vt, [-5.9, 110.7, 943.5]
    t0 = time.perf_counter()
    reference = locate(image, camera, mesh, hand, reach_deg=3.0)
    rows = [
        f"From the hand prior: `{reference.status}`, {reference.edge_samples} samples, "
        f"{100 * (reference.edge_share or 0):.0f} % on their edges, "
        f"RMS {reference.edge_rms_px} px, {time.perf_counter() - t0:.1f} s.",
        "",
        "| prior off by | status | seen edges from the hand prior's answer | s |",
        "|---|---|---|---|",
    ]
    rng = np.random.default_rng(7)
    for mm in (10, 20, 40, 60, 80, 100, 120):
        prior = moved_prior(hand, float(mm), 2.0, rng)
        t0 = time.perf_counter()
        located = locate(image, camera, mesh, prior, reach_mm=max(20.0, mm), reach_deg=3.0)
        apart = (
            "-"
            if located.obj2cam is None or reference.obj2cam is None
            else f"{image_distance_px(reference.obj2cam, located.obj2cam, mesh, camera):.1f} px"
        )
        rows.append(f"| {mm} mm, 2 deg | `{located.status}` | {apart} | {time.perf_counter() - t0:.1f} |")
    return rows
