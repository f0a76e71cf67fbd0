"""Views of surveyed cell features for a robot calibration: they tie the robot to the cell.

A board at an unknown pose cannot say where the robot's base is; the cell's components can, since
their placements are surveyed in the base frame. At a few poses around each task location's approach
the camera looks at its component, and :func:`~calib_core.look.find_points.find_points` locates the
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
from calib_core.frames import concat, invert
from calib_core.robot import solve_ik
from calib_core.robot.errors import UnreachableTargetError
from calib_core.robot.model import RobotModel
from calib_core.robot_calibration.observations import ObjectPoseView

SPREAD_MM, SPREAD_DEG = 60.0, 8.0
LOOK_DISTANCE_MM = 350.0
"""How far the camera stands from a component that has no task location (about a task's approach)."""
DISTINCT_MM = 50.0
"""Components closer than this to one already chosen add no new geometry (a fixture on its ORU)."""
MIN_FEATURES = 4


def surveyed_targets(robot: RobotModel, workcell) -> list[tuple[str, np.ndarray]]:
    """(component, camera2base (4, 4) mm of a central view) for every surveyed component the tie can
    use: each task location's component seen from its approach, then the other components with
    :data:`MIN_FEATURES` features or more, seen from :data:`LOOK_DISTANCE_MM` on the side facing the
    robot, leaving out one within :data:`DISTINCT_MM` of a chosen one. Two components alone leave the
    base's turn about the line through them to their edge fits' orientations; a third off that line
    fixes it by positions, which the edges measure far better."""
    chosen: list[tuple[str, np.ndarray]] = []
    where: list[np.ndarray] = []

    def take(name: str, camera2base: np.ndarray) -> None:
        centre = _centroid(workcell.component(name))
        if all(np.linalg.norm(centre - c) > DISTINCT_MM for c in where):
            chosen.append((name, camera2base))
            where.append(centre)

    for task in workcell.task_locations.values():
        if task.component is not None and len(workcell.component(task.component).features) >= MIN_FEATURES:
            take(task.component, _approach_camera(robot, task))
    eye = robot.fk(np.asarray(workcell.home_joints_deg, dtype=float), "camera")[:3, 3]
    for item in workcell.components:
        if len(item.features) >= MIN_FEATURES and item.name not in [n for n, _ in chosen]:
            take(item.name, _look_at(_centroid(item), LOOK_DISTANCE_MM, eye[2]))
    return chosen


def _centroid(item) -> np.ndarray:
    """The mean of the component's features (its own frame) in the base frame, mm."""
    points = np.array(list(item.features.values()), dtype=float)
    return item.item2world[:3, :3] @ points.mean(axis=0) + item.item2world[:3, 3]


def _approach_camera(robot: RobotModel, task) -> np.ndarray:
    """The modelled camera's pose (4, 4) mm when the TCP is at the task's approach."""
    tcp2flange = concat(robot.frame_placement("tcp"), invert(robot.frame_placement("flange")))
    cam2flange = concat(robot.frame_placement("camera"), invert(robot.frame_placement("flange")))
    return concat(cam2flange, invert(tcp2flange), task.approach2base)


def _look_at(target_mm: np.ndarray, distance_mm: float, eye_height_mm: float) -> np.ndarray:
    """A camera pose (4, 4) mm looking at ``target_mm`` from ``distance_mm`` along the line from the
    robot's base axis at ``eye_height_mm`` (the camera's height at home) to it, image up pointing
    up: the arm reaches out and down (or up) to it without folding its wrist."""
    out = np.array([target_mm[0], target_mm[1], target_mm[2] - eye_height_mm])
    z = out / max(np.linalg.norm(out), 1e-9)
    x = np.cross([0.0, 0.0, -1.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, y, z])
    T[:3, 3] = target_mm - distance_mm * z
    return T


def cell_view_joints(
    robot: RobotModel, workcell, intrinsics: Intrinsics, per_target: int = 3, seed: int = 0, collisions=None
) -> list[tuple[str, np.ndarray]]:
    """(component, joints deg) for ``per_target`` poses around each of :func:`surveyed_targets`'
    views, from which the modelled camera sees every feature of the component; with ``collisions``
    (a :class:`~calib_core.robot.collision.CollisionWorld`) only poses free of contacts."""
    rng = np.random.default_rng(seed)
    home = np.asarray(workcell.home_joints_deg, dtype=float)
    cam2flange = concat(robot.frame_placement("camera"), invert(robot.frame_placement("flange")))
    out = []
    for component, camera2base in surveyed_targets(robot, workcell):
        item = workcell.component(component)
        points = np.array(list(item.features.values()), dtype=float)
        try:
            q0 = solve_ik(robot, concat(invert(cam2flange), camera2base), home, frame="flange").q_deg
        except UnreachableTargetError:
            continue
        found, attempts = 0, 0
        while found < per_target and attempts < 30 * per_target:
            attempts += 1
            T = camera2base.copy()
            if found or attempts > 1:
                T[:3, :3] = (
                    Rotation.from_rotvec(np.radians(SPREAD_DEG) * rng.normal(size=3) / np.sqrt(3)).as_matrix()
                    @ T[:3, :3]
                )
                T[:3, 3] += rng.normal(0.0, SPREAD_MM / np.sqrt(3), 3)
            try:
                q = solve_ik(robot, concat(invert(cam2flange), T), q0, frame="flange").q_deg  # T: a camera2base
            except UnreachableTargetError:
                continue
            uv = project_points(points, concat(item.item2world, invert(robot.fk(q, "camera"))), intrinsics)
            if (
                intrinsics.contains(uv, margin_px=40).all()
                and np.all(robot.within_limits(q, 1.0))
                and (collisions is None or not collisions.check(q))
            ):
                out.append((component, q))
                found += 1
    return out


def cell_view(
    name: str,
    image: np.ndarray,
    joints_deg: np.ndarray,
    workcell,
    component: str,
    robot: RobotModel,
    intrinsics: Intrinsics,
    expected=None,
) -> ObjectPoseView | str:
    """``component`` located in ``image`` taken at ``joints_deg``: its pose from the edges with their
    covariance, as an :class:`ObjectPoseView` (the component surveyed in the base frame); or the
    reason there is none. ``robot`` places the modelled camera
    (the nominal robot, or one calibrated on a board already, which starts the search closer)."""
    from calib_core.look.find_points import find_points

    item = workcell.component(component)
    obj2cam_model = concat(item.item2world, invert(robot.fk(joints_deg, "camera")))
    result = find_points(image, intrinsics, item, obj2cam_model, expected=expected)
    if result.edges is None or not result.edges.settled:
        return f"{name}: {component} not located ({result.message})"
    if not np.all(np.isfinite(result.edges.covariance)):
        return f"{name}: {component}'s edge fit gives no covariance"
    points = np.array(list(item.features.values()), dtype=float)
    return ObjectPoseView(
        name,
        np.asarray(joints_deg, dtype=float),
        result.edges.obj2cam,
        result.edges.covariance,
        item.item2world,
        points_mm=points,
    )
