"""A corner found from its edges through a strong lens: the edges are straight in the ideal pinhole
image, curved in the camera's; the lines are fitted where they are straight."""

import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project, undistort_pixels, unproject
from calib_core.look.feature_detectors import Detection, detect_corner_from_edges

LENS = Intrinsics(
    fu=600.0, fv=600.0, cx=320.0, cy=240.0, width=640, height=480, distortion=(-0.45, 0.15, 0.0, 0.0, 0.0)
)


def _distorted(ideal_px: np.ndarray) -> np.ndarray:
    return project(unproject(ideal_px, LENS, undistort=False), LENS)


def _image_of_a_corner(corner_ideal: np.ndarray) -> np.ndarray:
    """The camera's image (h, w) of a bright quadrant whose corner is at ``corner_ideal`` (ideal px),
    each pixel the mean of 4 x 4 samples, as a sensor integrates."""
    s = (np.arange(4) + 0.5) / 4 - 0.5
    v, u = np.mgrid[0 : LENS.height, 0 : LENS.width].astype(float)
    total = np.zeros_like(u)
    for du in s:
        for dv in s:
            ideal = undistort_pixels(np.column_stack([(u + du).ravel(), (v + dv).ravel()]), LENS).reshape(
                u.shape + (2,)
            )
            total += (ideal[..., 0] > corner_ideal[0]) & (ideal[..., 1] > corner_ideal[1])
    return (40 + 160 * total / 16).astype(np.uint8)


def test_a_corner_far_from_the_centre_is_found_where_its_straight_edges_meet():
    corner_ideal = np.array([90.0, 70.0])
    image = _image_of_a_corner(corner_ideal)
    truth = _distorted(corner_ideal[None])[0]
    arms = [
        _distorted(np.array([corner_ideal + [60.0, 0.0]]))[0],
        _distorted(np.array([corner_ideal + [0.0, 60.0]]))[0],
    ]
    through_lens = detect_corner_from_edges(image, truth, arms, search_px=3.0, lens=LENS)
    plain = detect_corner_from_edges(image, truth, arms, search_px=3.0)
    assert isinstance(through_lens, Detection) and isinstance(plain, Detection)
    error_lens = np.linalg.norm(through_lens.uv_px - truth)
    error_plain = np.linalg.norm(plain.uv_px - truth)
    assert error_lens < 0.1, error_lens
    assert error_lens < error_plain, (error_lens, error_plain)
