"""Views of surveyed cell features for a robot calibration: they tie the robot to the cell.

A board at an unknown pose cannot say where the robot's base is; the cell's components can, since
their placements are surveyed in the base frame. At a few poses around each task location's approach
the camera looks at its component, and :func:`~calib_core.vision.find_points.find_points` locates the
component in the frame (through the given intrinsics, never the truth). The observation is the
component's pose from its edges (the model-based refinement over hundreds of samples) with that
fit's covariance, not single features: the edges carry less bias than any one detector (0.2-0.8 px on
corners and bosses, docs/benchmarks/find_points.md), and the covariance says how far to trust them.
A view whose edge fit does not settle is left out, with the reason.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics import Intrinsics
from calib_core.camera.projection import project_points
from calib_core.frames import invert
from calib_core.robot import solve_ik
from calib_core.robot.errors import UnreachableTargetError
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.observations import ObjectPoseView

SPREAD_MM, SPREAD_DEG = 60.0, 8.0


def cell_view_joints(robot: RobotModel, workcell, intrinsics: Intrinsics, per_target: int = 3, seed: int = 0) -> list[tuple[str, np.ndarray]]:
    """(component, joints deg) for ``per_target`` poses around each task location's approach from
    which the modelled camera sees every feature of the task's component."""
    rng = np.random.default_rng(seed)
    home = np.asarray(workcell.home_joints_deg, dtype=float)
    out = []
    for task in workcell.task_locations.values():
        if task.component is None:
            continue
        item = workcell.component(task.component)
        points = np.array(list(item.features.values()), dtype=float)
        if len(points) < 4:
            continue
        try:
            q0 = solve_ik(robot, task.approach2base, home).q_deg
        except UnreachableTargetError:
            continue
        found, attempts = 0, 0
        while found < per_target and attempts < 30 * per_target:
            attempts += 1
            T = task.approach2base.copy()
            if found or attempts > 1:
                T[:3, :3] = Rotation.from_rotvec(np.radians(SPREAD_DEG) * rng.normal(size=3) / np.sqrt(3)).as_matrix() @ T[:3, :3]
                T[:3, 3] += rng.normal(0.0, SPREAD_MM / np.sqrt(3), 3)
            try:
                q = solve_ik(robot, T, q0).q_deg
            except UnreachableTargetError:
                continue
            uv = project_points(points, invert(robot.fk(q, "camera")) @ item.item2world, intrinsics)
            if intrinsics.contains(uv, margin_px=40).all():
                out.append((task.component, q))
                found += 1
    return out


def cell_view(name: str, image: np.ndarray, joints_deg: np.ndarray, workcell, component: str, robot: RobotModel, intrinsics: Intrinsics, expected=None) -> ObjectPoseView | str:
    """``component`` located in ``image`` taken at ``joints_deg``: its pose from the edges with their
    covariance, as an :class:`ObjectPoseView` (the component surveyed in the base frame); or the
    reason there is none. ``robot`` places the modelled camera
    (the nominal robot, or one calibrated on a board already, which starts the search closer)."""
    from calib_core.vision.find_points import find_points

    item = workcell.component(component)
    obj2cam_model = invert(robot.fk(joints_deg, "camera")) @ item.item2world
    result = find_points(image, intrinsics, item, obj2cam_model, expected=expected)
    if result.edges is None or not result.edges.settled:
        return f"{name}: {component} not located ({result.message})"
    if not np.all(np.isfinite(result.edges.covariance)):
        return f"{name}: {component}'s edge fit gives no covariance"
    return ObjectPoseView(name, np.asarray(joints_deg, dtype=float), result.edges.obj2cam, result.edges.covariance, item.item2world)
