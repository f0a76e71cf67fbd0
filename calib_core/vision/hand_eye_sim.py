"""Hand-eye data from the simulated test bed: the robot looks at a board from several poses."""

from __future__ import annotations

import numpy as np

from calib_core.frames import make_transform
from calib_core.testbed.sim_camera import SimulatedCamera
from calib_core.testbed.test_bed import TestBed
from calib_core.vision.board import BoardSpec, board_item
from calib_core.vision.board_placement import FACING_ROBOT, board_from_centre, board_view_joints

def board_facing_robot(spec: BoardSpec) -> np.ndarray:
    """``board2base``: the board upright 950 mm in front of the bundled robot, centred at 1 m
    height, facing -x (the bundled cell's ``hand_eye_board``)."""
    return board_from_centre(spec, make_transform(FACING_ROBOT, [950.0, 0.0, 1000.0]))


def hand_eye_poses(bed: TestBed, spec: BoardSpec, board2base: np.ndarray, n: int = 10, seed: int = 0) -> list[np.ndarray]:
    """Joint vectors (deg) from which the modelled camera of the test bed looks at the board."""
    return board_view_joints(bed.model_robot, bed.workcell.home_joints_deg, spec, board2base, n, seed)


def simulated_hand_eye_images(bed: TestBed, spec: BoardSpec, joints: list[np.ndarray], board2base: np.ndarray, seed: int = 0):
    """(name, RGB image, commanded joints) for each pose, seen by the true camera of the test bed."""
    board = board_item(spec, board2base)
    camera = SimulatedCamera(bed.intrinsics, lambda q: bed.true_scene(q) + [board], bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed)
    images = []
    for k, q in enumerate(joints):
        bed.joints_deg = np.asarray(q, dtype=float)
        images.append((f"pose_{k + 1:02d}", camera.read().image, bed.joints_deg.copy()))
    camera.close()
    return images
