"""Board views from the simulated camera: the truth known, for tests, the bench and the demo."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.frames import make_transform
from videocal_sim.sim_camera import CameraLook, SimulatedCamera
from calib_core.vision.board import BoardSpec, board_item


def board_view_poses(n: int, spec: BoardSpec, seed: int = 0) -> list[np.ndarray]:
    """``n`` camera poses (cam2board, 4 x 4 mm) that see the whole board, tilted up to 35 deg,
    from 350 to 650 mm, with the board in different parts of the image."""
    rng = np.random.default_rng(seed)
    w, h = spec.size_mm
    centre = np.array([w / 2, h / 2, 0.0])
    poses = []
    for k in range(n):
        tilt = Rotation.from_euler(
            "xyz", [rng.uniform(-35, 35), rng.uniform(-35, 35), rng.uniform(-20, 20)], degrees=True
        )
        distance = rng.uniform(350, 650)
        # Look at a point near the board centre, offset so the board lands in different image regions.
        aim = centre + np.array([rng.uniform(-0.5, 0.5) * w, rng.uniform(-0.5, 0.5) * h, 0.0])
        R = tilt.as_matrix()
        position = aim - distance * R[:, 2]
        poses.append(make_transform(R, position))
    return poses


def simulated_board_images(
    intrinsics: Intrinsics, spec: BoardSpec, n: int = 15, seed: int = 0, look: CameraLook | None = None
) -> list[tuple[str, np.ndarray]]:
    """``n`` images (name, RGB) of the board seen by a camera with ``intrinsics``."""
    item = board_item(spec, np.eye(4))
    poses = board_view_poses(n, spec, seed)
    state = {"pose": poses[0]}
    camera = SimulatedCamera(
        intrinsics,
        lambda q: [item],
        lambda q: state["pose"],
        lambda: np.zeros(6),
        look=look or CameraLook(background=(0.35, 0.36, 0.38)),
        seed=seed,
    )
    images = []
    for k, pose in enumerate(poses):
        state["pose"] = pose
        images.append((f"sim_{k + 1:02d}", camera.read().image))
    camera.close()
    return images
