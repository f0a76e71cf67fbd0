"""Synthetic board views for the robot calibration's tests (no rendering): the simulated cold cell, the board placed
in it, the joints of poses that see it, and the pixels of its corners through any camera pose."""

from __future__ import annotations

import numpy as np

from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.robot_calibration.observations import PoseView
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell, board_view_joints
from calib_core.workcell import load_workcell
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

SPEC = parse_board(DEFAULT_SPEC)


def cold_cell_with_board(poses: int = 50, seed: int = 3):
    """The bundled cell's test bed with typical robot errors (seed 0), the board's placement (4, 4, mm, base frame)
    and ``poses`` joint vectors (deg) that see it: ``(bed, board2base, joints)``."""
    cell = load_workcell()
    bed = TestBed.create(cell, errors=RobotErrors.typical(0))
    board2base = board_in_cell(SPEC, cell, bed.model_robot)
    joints = board_view_joints(bed.model_robot, cell.home_joints_deg, SPEC, board2base, poses, seed=seed)
    return bed, board2base, joints


def board_views(cam2base_at, joints, board2base, intrinsics, noise_px=0.0, seed=0) -> list[PoseView]:
    """A :class:`PoseView` per joint vector: the board's corners seen by the camera at ``cam2base_at(q)`` (4, 4, mm),
    with Gaussian pixel noise of ``noise_px`` (seeded)."""
    rng = np.random.default_rng(seed)
    pts = SPEC.corners_mm()
    out = []
    for k, q in enumerate(joints):
        px = project(apply(invert(cam2base_at(q)) @ board2base, pts), intrinsics)
        out.append(PoseView(f"v{k}", np.asarray(q), pts, px + rng.normal(0.0, noise_px, px.shape)))
    return out
