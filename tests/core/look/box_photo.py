"""OpenCV's real-time pose tutorial photo of a printed box, its mesh, the tutorial's nominal camera and a prior
picked by hand."""

from __future__ import annotations

from pathlib import Path

from calib_core.camera.intrinsics import Intrinsics

DATA = Path(__file__).resolve().parents[2] / "data" / "third_party" / "opencv_samples"
PHOTO, BOX = DATA / "resized_IMG_3875.JPG", DATA / "box.ply"
TUTORIAL_CAMERA = Intrinsics(718 * 45 / 22.3, 480 * 45 / 14.9, 359.0, 240.0, 718, 480)

# The box's pose from six of its corners picked by hand in the photo (about 4 px RMS: a rough prior)
HAND_PRIOR = {
    "R_obj2cam": [[0.7512, -0.6587, -0.0433], [-0.3824, -0.3808, -0.8419], [0.538, 0.649, -0.5379]],
    "t_obj2cam_mm": [-5.9, 110.7, 943.5],
}
