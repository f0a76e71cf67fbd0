"""Where a calibration board stands in the cell, and the robot poses that view it.

Only the model robot is used: these are plans, made the same way on a real and a simulated site.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.frames import concat, invert, make_transform
from calib_core.robot import UnreachableTargetError, solve_ik
from calib_core.robot.model import RobotModel
from calib_core.robot.reach import reach_of
from calib_core.vision.board import BoardSpec

VIEW_DISTANCE_MM = (420.0, 600.0)
"""How far the camera stands from the board in the planned views."""

# Board x (columns) along base -y, y (rows) down along base -z, z (into the board) along base +x:
# upright, facing the robot, which stands on the base's -x side of it.
FACING_ROBOT = np.column_stack([[0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])


def board_from_centre(spec: BoardSpec, centre2base: np.ndarray) -> np.ndarray:
    """``board2base`` (its first corner) of a board whose centre frame is ``centre2base`` (4, 4) mm."""
    w, h = spec.size_mm
    R = centre2base[:3, :3]
    return make_transform(R, centre2base[:3, 3] - R @ np.array([w / 2, h / 2, 0.0]))


def board_in_front_of_robot(spec: BoardSpec, robot: RobotModel, home_deg=None) -> np.ndarray:
    """``board2base`` (4, 4) mm: upright on the base's +x axis, facing the robot, far enough that the
    camera views it from :data:`VIEW_DISTANCE_MM` with the flange at about 45 % of the reach."""
    reach, height = reach_of(robot)
    centre = np.array([0.45 * reach + np.mean(VIEW_DISTANCE_MM), 0.0, max(height, 0.25 * reach)])
    return board_from_centre(spec, make_transform(FACING_ROBOT, centre))


def board_in_cell(spec: BoardSpec, workcell, robot: RobotModel) -> np.ndarray:
    """``board2base`` (4, 4) mm: where the workcell's ``hand_eye_board`` says, else in front of the robot."""
    centre = workcell.meta.get("hand_eye_board_centre")
    return board_from_centre(spec, centre) if centre is not None else board_in_front_of_robot(spec, robot)


def board_view_joints(
    robot: RobotModel,
    start_deg,
    spec: BoardSpec,
    board2base: np.ndarray,
    n: int = 10,
    seed: int = 0,
    off_centre_deg: float = 0.0,
) -> list[np.ndarray]:
    """Joint vectors (deg/mm) from which the modelled camera looks at the board from different
    directions, rolled about its axis: reachable ones only, each IK seeded from the one before.
    ``off_centre_deg``: the camera also panned and tilted about its own centre by up to this much,
    so the board lands off the image's centre (views that reach the image's corners, where the
    lens distortion is largest and a calibration learns it)."""
    rng = np.random.default_rng(seed)
    w, h = spec.size_mm
    centre = board2base[:3, :3] @ np.array([w / 2, h / 2, 0.0]) + board2base[:3, 3]
    cam2flange = concat(robot.frame_placement("camera"), invert(robot.frame_placement("flange")))
    q = np.asarray(start_deg, dtype=float).copy()
    out: list[np.ndarray] = []
    attempts = 0
    while len(out) < n and attempts < 20 * n:
        attempts += 1
        # Camera axis toward the board centre from a direction within 30 deg of the board normal.
        tilt = Rotation.from_euler("yz", [rng.uniform(-30, 30), rng.uniform(-30, 30)], degrees=True)
        view_dir = tilt.apply(board2base[:3, 2])  # into the board
        position = centre - rng.uniform(*VIEW_DISTANCE_MM) * view_dir
        z = view_dir / np.linalg.norm(view_dir)
        x = np.cross([0.0, 0.0, -1.0], z)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        roll = Rotation.from_rotvec(np.radians(rng.uniform(-35, 35)) * z).as_matrix()
        aim = (
            Rotation.from_euler("xy", rng.uniform(-off_centre_deg, off_centre_deg, 2), degrees=True).as_matrix()
            if off_centre_deg
            else np.eye(3)
        )
        cam2base = make_transform(roll @ np.column_stack([x, y, z]) @ aim, position)
        try:
            sol = solve_ik(robot, concat(invert(cam2flange), cam2base), q, frame="flange", extra_seeds=4)
        except UnreachableTargetError:
            continue
        q = sol.q_deg
        out.append(q)
    return out
