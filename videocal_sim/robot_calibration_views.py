"""Board views for a robot calibration from the simulated test bed: the board put up in the cell
where the plan says, the robot stepped through the planned poses, each frame rendered by the true
camera and detected as a real one would be. The truth places the board and renders; what comes
out is only the detected corners and the commanded joints."""

from __future__ import annotations

import numpy as np

from calib_core.robot_calibration.identify_robot import CellFrame
from calib_core.robot_calibration.observations import PoseView
from videocal_sim.sim_camera import SimulatedCamera
from videocal_sim.test_bed import TestBed
from calib_core.vision.board import board_item
from calib_core.vision.intrinsics_calibration import BoardView, detect_view


def simulated_pose_views(
    bed: TestBed, spec, board2base: np.ndarray, joints: list[np.ndarray], seed: int = 0, progress=None
) -> tuple[list[BoardView], list[PoseView], list[str]]:
    """(board views, pose views, rejections) at ``joints`` (commanded, deg) with the board at ``board2base``."""
    bed.extra_items = [board_item(spec, board2base)]
    camera = SimulatedCamera(
        bed.intrinsics, bed.true_scene, bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed
    )
    detect = spec.detector()
    corners = spec.corners_mm()
    board_views, pose_views, rejected = [], [], []
    try:
        for k, q in enumerate(joints):
            bed.joints_deg = np.asarray(q, dtype=float)
            name = f"pose_{k + 1:02d}"
            view = detect_view(name, camera.read().image, spec, detect)
            if isinstance(view, BoardView):
                board_views.append(view)
                pose_views.append(PoseView(name, bed.joints_deg.copy(), corners[view.ids], view.corners_px))
            else:
                rejected.append(f"{name}: {view.reason}")
            if progress is not None:
                progress(k + 1, len(joints))
    finally:
        camera.close()
        bed.extra_items = []
    return board_views, pose_views, rejected


def simulated_cell_frames(
    bed: TestBed, targets: list[tuple[str, np.ndarray]], seed: int = 0, progress=None
) -> list[CellFrame]:
    """Frames of surveyed features (:mod:`calib_core.robot_calibration.cell_views`) at ``targets``
    ((component, commanded joints deg)), rendered by the true camera; the identification's driver
    locates them as it does a real camera's."""
    camera = SimulatedCamera(
        bed.intrinsics, bed.true_scene, bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed + 1
    )
    frames = []
    try:
        for k, (component, q) in enumerate(targets):
            bed.joints_deg = np.asarray(q, dtype=float)
            frames.append(
                CellFrame(component, bed.joints_deg.copy(), camera.read().image, f"cell_{k + 1:02d}_{component}")
            )
            if progress is not None:
                progress(k + 1, len(targets))
    finally:
        camera.close()
    return frames
