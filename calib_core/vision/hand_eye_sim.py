"""Hand-eye data from the simulated test bed: the robot looks at a board from several poses."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.frames import make_transform
from calib_core.robot import UnreachableTargetError, solve_ik
from calib_core.testbed.sim_camera import SimulatedCamera
from calib_core.testbed.test_bed import TestBed
from calib_core.vision.board import BoardSpec, board_item

def board_facing_robot(spec: BoardSpec) -> np.ndarray:
    """``board2base``: the board upright 950 mm in front of the robot, centred at 1 m height, facing -x."""
    w, h = spec.size_mm
    # Board x (columns) along base -y, y (rows) down along base -z, z (into the board) along base +x.
    R = np.column_stack([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    centre = np.array([950.0, 0.0, 1000.0])
    return make_transform(R, centre - R @ np.array([w / 2, h / 2, 0.0]))


def hand_eye_poses(bed: TestBed, spec: BoardSpec, board2base: np.ndarray, n: int = 10, seed: int = 0) -> list[np.ndarray]:
    """Joint vectors (deg) from which the modelled camera looks at the board from different directions,
    rolled about its axis: reachable ones only."""
    rng = np.random.default_rng(seed)
    w, h = spec.size_mm
    centre = board2base[:3, :3] @ np.array([w / 2, h / 2, 0.0]) + board2base[:3, 3]
    cam2flange = np.linalg.inv(bed.model_robot.frame_placement("flange")) @ bed.model_robot.frame_placement("camera")
    q = bed.workcell.home_joints_deg.copy()
    out = []
    attempts = 0
    while len(out) < n and attempts < 20 * n:
        attempts += 1
        # Camera axis toward the board centre from a direction within 30 deg of the board normal, 420-600 mm away.
        tilt = Rotation.from_euler("yz", [rng.uniform(-30, 30), rng.uniform(-30, 30)], degrees=True)
        view_dir = tilt.apply(board2base[:3, 2])  # into the board
        distance = rng.uniform(420, 600)
        position = centre - distance * view_dir
        z = view_dir / np.linalg.norm(view_dir)
        x = np.cross([0.0, 0.0, -1.0], z)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        roll = Rotation.from_rotvec(np.radians(rng.uniform(-35, 35)) * z).as_matrix()
        cam2base = make_transform(roll @ np.column_stack([x, y, z]), position)
        flange2base = cam2base @ np.linalg.inv(cam2flange)
        try:
            sol = solve_ik(bed.model_robot, flange2base, q, frame="flange", extra_seeds=4)
        except UnreachableTargetError:
            continue
        q = sol.q_deg
        out.append(q)
    return out


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
