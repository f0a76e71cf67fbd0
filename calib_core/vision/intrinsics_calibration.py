"""Camera intrinsics (fu, fv, cx, cy and k1 k2 p1 p2 k3) from views of a calibration target
(ChArUco, chessboard, circle grid, ArUco grid: :func:`calib_core.vision.board.parse_board`), with
OpenCV's detectors and ``calibrateCameraExtended``: per-view errors, the standard deviation of every
parameter, coverage of the image, and advice on what views to add."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import cv2
import numpy as np

from calib_core.camera.intrinsics import Intrinsics
from calib_core.vision.target_detection import DetectorSettings
from calib_core.errors import VideocalError

MIN_CORNERS = 8
MIN_VIEWS = 3
PARAMETERS = ("fu", "fv", "cx", "cy", "k1", "k2", "p1", "p2", "k3")


class CalibrationInputError(VideocalError, ValueError):
    """Views that cannot give a calibration (too few, all rejected); the message says why."""


@dataclass(frozen=True)
class BoardView:
    """Corners of one view: ``corners_px`` (n, 2) and their ``ids`` (n,) on the board."""

    name: str
    corners_px: np.ndarray
    ids: np.ndarray
    image_size: tuple[int, int]


@dataclass(frozen=True)
class RejectedView:
    name: str
    reason: str


@dataclass(frozen=True)
class IntrinsicsCalibration:
    """The result: ``intrinsics``; ``rms_px`` over all corners; ``per_view_rms_px`` per view;
    ``std`` the 1-sigma of each parameter (px for fu, fv, cx, cy; unitless for distortion);
    ``coverage`` the fraction of image cells holding a corner; ``used``/``rejected`` views."""

    intrinsics: Intrinsics
    rms_px: float
    per_view_rms_px: dict[str, float]
    std: dict[str, float]
    coverage: float
    used: list[str]
    rejected: list[RejectedView] = field(default_factory=list)
    advice: list[str] = field(default_factory=list)


MIN_SIDE_PX = 32
"""An image with a side shorter than this (px) cannot hold a board's corners: it is rejected, not handed to OpenCV
(whose adaptive threshold fails an assertion on a 1 x 1 picture)."""
MAX_ASPECT = 5.0
"""The longest side of a view at most this many times its shortest."""


def detect_view(name: str, image: np.ndarray, spec, detector=None) -> BoardView | RejectedView:
    """Find the target's points in one image (RGB or grey); ``detector`` from ``spec.detector(settings)``
    (made once for many images), else one with the default settings."""
    h, w = image.shape[:2]
    if min(h, w) < MIN_SIDE_PX:
        return RejectedView(name, f"the image is {w} x {h} px: too small to hold a board")
    if max(h, w) > MAX_ASPECT * min(h, w):
        # no camera takes such a picture (a damaged file decodes so: 640 x 14304), and OpenCV's detectors allocate
        # past 2 GB on one
        return RejectedView(
            name,
            f"the image is {w} x {h} px: not a camera's picture (sides more than {MAX_ASPECT:g} to 1; a damaged file?)",
        )
    grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_RGB2GRAY)
    found = (detector or spec.detector())(grey)
    size = (grey.shape[1], grey.shape[0])
    if len(found.ids) == 0:
        if found.markers_seen == 0 or spec.kind != "charuco":
            return RejectedView(name, "no board found")
        return RejectedView(
            name,
            f"{found.markers_seen} markers seen but no chessboard corner: wrong board spec, or the board is too small "
            "or blurred",
        )
    if len(found.ids) < MIN_CORNERS:
        return RejectedView(
            name,
            f"only {len(found.ids)} corners seen (at least {MIN_CORNERS} needed): the board is mostly outside the "
            "image or hidden",
        )
    return BoardView(name, found.corners_px, found.ids, size)


def detect_views(
    images: Iterable[tuple[str, np.ndarray]], spec, settings: DetectorSettings | None = None
) -> tuple[list[BoardView], list[RejectedView]]:
    detector = spec.detector(settings)
    views, rejected = [], []
    size = None
    for name, image in images:
        result = detect_view(name, image, spec, detector)
        if isinstance(result, BoardView):
            if size is None:
                size = result.image_size
            elif result.image_size != size:
                rejected.append(
                    RejectedView(
                        name,
                        f"image size {result.image_size[0]}x{result.image_size[1]} differs from the first view's "
                        f"{size[0]}x{size[1]}",
                    )
                )
                continue
            views.append(result)
        else:
            rejected.append(result)
    return views, rejected


def coverage(views: list[BoardView], image_size: tuple[int, int], grid: tuple[int, int] = (8, 6)) -> float:
    """Fraction of a ``grid`` of image cells that hold at least one detected corner."""
    w, h = image_size
    hit = np.zeros(grid[::-1], dtype=bool)
    for v in views:
        cols = np.clip((v.corners_px[:, 0] / w * grid[0]).astype(int), 0, grid[0] - 1)
        rows = np.clip((v.corners_px[:, 1] / h * grid[1]).astype(int), 0, grid[1] - 1)
        hit[rows, cols] = True
    return float(hit.mean())


RADIAL_TERMS = 2
"""k1 and k2 by default, k3 held at zero (as ROS's camera_calibration does): with views that do not
reach the image's corners a third radial term is free to bend the model where no corner was seen
(on the cold cell's planned views it made k2 0.37 against a true 0.08 and put a component seen near
the image's top 0.5-2 mm off in depth)."""


def calibrate_intrinsics(
    views: list[BoardView],
    spec,
    *,
    distortion: bool = True,
    radial_terms: int = RADIAL_TERMS,
    rejected: list[RejectedView] | None = None,
) -> IntrinsicsCalibration:
    """Calibrate from detected views; ``distortion=False`` fits the pinhole only (what the paper's
    tool had); ``radial_terms`` 2 (k1, k2) or 3 (k1, k2, k3; for wide lenses, with views covering the
    image's corners). Tangential terms p1, p2 are fitted with any distortion."""
    rejected = list(rejected or [])
    if radial_terms not in (2, 3):
        raise CalibrationInputError(f"radial_terms must be 2 (k1 k2) or 3 (k1 k2 k3), got {radial_terms}")
    if len(views) < MIN_VIEWS:
        why = "; ".join(f"{r.name}: {r.reason}" for r in rejected[:5])
        raise CalibrationInputError(
            f"{len(views)} usable board views, at least {MIN_VIEWS} needed" + (f" (rejected: {why})" if why else "")
        )
    size = views[0].image_size
    corners3d = spec.corners_mm()
    object_points = [corners3d[v.ids].astype(np.float32) for v in views]
    image_points = [v.corners_px.astype(np.float32).reshape(-1, 1, 2) for v in views]
    flags = 0
    if not distortion:
        flags |= cv2.CALIB_FIX_K1 | cv2.CALIB_FIX_K2 | cv2.CALIB_FIX_K3 | cv2.CALIB_ZERO_TANGENT_DIST
    elif radial_terms == 2:
        flags |= cv2.CALIB_FIX_K3
    rms, K, dist, _, _, std_intr, _, per_view = cv2.calibrateCameraExtended(
        object_points, image_points, size, None, None, flags=flags
    )
    dist = np.asarray(dist, dtype=float).ravel()[:5]
    intr = Intrinsics(
        float(K[0, 0]),
        float(K[1, 1]),
        float(K[0, 2]),
        float(K[1, 2]),
        size[0],
        size[1],
        tuple(np.pad(dist, (0, 5 - len(dist)))),
    )
    s = np.asarray(std_intr, dtype=float).ravel()
    std = {"fu": s[0], "fv": s[1], "cx": s[2], "cy": s[3], "k1": s[4], "k2": s[5], "p1": s[6], "p2": s[7], "k3": s[8]}
    result = IntrinsicsCalibration(
        intr,
        float(rms),
        {v.name: float(e) for v, e in zip(views, np.asarray(per_view).ravel())},
        {k: float(v) for k, v in std.items()},
        coverage(views, size),
        [v.name for v in views],
        rejected,
    )
    return IntrinsicsCalibration(**{**result.__dict__, "advice": advice(result)})


def advice(result: IntrinsicsCalibration) -> list[str]:
    """What the operator should do next, in words."""
    out = []
    if result.coverage < 0.7:
        out.append(
            f"the corners cover {100 * result.coverage:.0f} % of the image: add views with the board near the image "
            "corners and edges, where distortion is strongest"
        )
    if len(result.used) < 10:
        out.append(f"{len(result.used)} views: 10-20 views at different tilts give a stable calibration")
    rel = result.std["fu"] / result.intrinsics.fu
    if rel > 0.002:
        out.append(f"fu is known to {100 * rel:.2f} % (1-sigma): add views tilted 20-40 deg about both axes")
    if result.std["cx"] > 1.0 or result.std["cy"] > 1.0:
        out.append(
            f"the principal point is known to {max(result.std['cx'], result.std['cy']):.1f} px: add tilted views"
        )
    worst = max(result.per_view_rms_px.items(), key=lambda kv: kv[1])
    if worst[1] > 3 * max(result.rms_px, 0.05):
        out.append(
            f"view {worst[0]} fits poorly ({worst[1]:.2f} px against {result.rms_px:.2f} px overall): blurred or "
            "mis-detected, consider removing it"
        )
    if not out:
        out.append("good enough: every parameter is well determined and the image is covered")
    return out
