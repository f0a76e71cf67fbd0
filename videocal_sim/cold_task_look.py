"""The last step of the cold cell's chain: one look at a task location on the calibrated model.

The calibrated robot (its joints, camera and tool) goes to the task location (or its approach); Find
points' edge refinement measures the task's component through the calibrated intrinsics (Calibrate on edges); the
end effector's displacement there is the correction (``Δ``, :mod:`calib_core.calibration.end_effector`);
the robot is commanded to ``Δ^-1 . target`` through the calibrated model. The truth places the robot
and renders the frame, and scores where the true TCP ends up: nothing else reads it.

The score is against the task where it truly is: on its component as the component really stands,
within the survey's 0.1 mm of the workcell file (a task is done on the part, not on its drawing). The
calibrated model alone aims at the surveyed place, so its figure includes the survey's error; the
look sees the part itself.
"""

from __future__ import annotations

import numpy as np

from calib_core.calibration.end_effector import end_effector_from_solution, shared_shift_covariance
from calib_core.frames import concat, invert, pose_difference
from calib_core.render.model_view import ModelView
from calib_core.robot import solve_ik
from calib_core.robot.visuals import RobotVisuals
from videocal_sim.sim_camera import SimulatedCamera
from calib_core.look.edge_solution import edge_solution
from calib_core.look.find_points import find_points


def look_at_task(
    bed,
    robot,
    intrinsics,
    task_name: str | None = None,
    seed: int = 0,
    model_covariance=None,
    placement_sigma_mm: float = 0.0,
    from_where: str = "task",
    tool=None,
) -> dict:
    """Figures of one look at ``task_name`` (default: the cell's first task) with the calibrated
    ``robot`` and ``intrinsics``, made from the task location itself (``from_where="task"``, as the
    paper and ``videocal demo`` do) or from its approach (``"approach"``): the TCP's true error at the task commanded
    through the calibrated
    model without the look and with it, the look's own 1-sigma, and whether the error is within 3 sigma.
    ``model_covariance(q_deg)``: the calibrated model's TCP covariance (6, 6: mm, deg) at joints; with
    it the look is also fused with the model (:mod:`calib_core.calibration.look_fusion`), the
    component's placement known to ``placement_sigma_mm`` (1-sigma per axis), and scored. ``tool``: the
    :class:`~calib_core.robot_calibration.camera_to_tool.CameraToTool` the robot's TCP came from; its
    covariance is added to the look's and to the fused one (look and model share the tool's error, so it
    is added after the fusion, not weighed in it)."""
    cell = bed.workcell
    task = cell.task(task_name) if task_name else next(iter(cell.task_locations.values()))
    item = cell.component(task.component)
    home = np.asarray(cell.home_joints_deg, dtype=float)
    if from_where not in ("task", "approach"):
        raise ValueError(f"look_at_task: from_where must be 'task' or 'approach', not {from_where!r}")
    q_approach = solve_ik(robot, task.approach2base, home).q_deg
    if from_where == "task":
        q_approach = solve_ik(robot, task.tcp2base, q_approach).q_deg
    bed.joints_deg = q_approach
    camera = SimulatedCamera(
        bed.intrinsics, bed.true_scene, bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed + 7
    )
    view = ModelView(intrinsics)
    try:
        image = camera.read().image
        cam2world_model = robot.fk(q_approach, "camera")
        obj2cam_model = concat(item.item2world, invert(cam2world_model))
        expected = view.of_cell(cell.components, RobotVisuals.from_robot(robot), q_approach, item.item2world)
        found = find_points(image, intrinsics, item, obj2cam_model, expected=expected)
    finally:
        camera.close()
        view.close()
    out = {
        "task": task.name,
        "looked_from": from_where,
        "found": bool(found.edges is not None and found.edges.settled),
        "message": found.message,
    }
    true_item = next((c for c in bed.true_components or () if c.name == item.name), item)
    task_true = concat(task.tcp2base, invert(item.item2world), true_item.item2world)

    def error(q):
        d, r = pose_difference(bed.true_robot.fk(q, "tcp"), task_true)
        return d, r, [round(float(np.linalg.norm(d)), 4), round(float(np.linalg.norm(r)), 5)]

    out["survey_error_mm"] = round(float(np.linalg.norm(task_true[:3, 3] - task.tcp2base[:3, 3])), 4)
    q_plain = solve_ik(robot, task.tcp2base, q_approach).q_deg
    out["calibrated_model_only_mm_deg"] = error(q_plain)[2]
    if not out["found"]:
        return out
    solution = edge_solution(found.edges, intrinsics)
    features = np.array(list(item.features.values()), dtype=float).reshape(-1, 3)
    estimate = end_effector_from_solution(
        solution,
        item.item2world,
        cam2world_model,
        robot.fk(q_approach, "tcp"),
        shared_covariance=shared_shift_covariance(solution.obj2cam, features, intrinsics),
    )
    q_task = solve_ik(robot, concat(task.tcp2base, invert(estimate.delta_base)), q_approach).q_deg
    d, r, after = error(q_task)
    tool_covariance = tool.covariance_in_base(cam2world_model) if tool is not None else None
    look_std = (
        np.sqrt(np.diag(estimate.covariance + tool_covariance))
        if tool_covariance is not None and estimate.covariance is not None
        else None
    )
    sigma_mm = float(np.linalg.norm(estimate.std_displacement_mm if look_std is None else look_std[:3]))
    sigma_deg = float(np.linalg.norm(estimate.std_rotation_deg if look_std is None else look_std[3:]))
    out.update(
        {
            "after_look_mm_deg": after,
            "look_sigma_mm_deg": [round(sigma_mm, 4), round(sigma_deg, 5)],
            "look_displacement_mm": [round(float(v), 4) for v in estimate.displacement_mm],
            "within_3_sigma": bool(np.linalg.norm(d) <= 3 * sigma_mm and np.linalg.norm(r) <= 3 * sigma_deg),
        }
    )
    if model_covariance is not None and estimate.covariance is not None:
        from calib_core.calibration.look_fusion import fuse_look

        fused = fuse_look(estimate, model_covariance(q_approach), placement_sigma_mm=placement_sigma_mm)
        q_fused = solve_ik(robot, concat(task.tcp2base, invert(fused.delta_base)), q_approach).q_deg
        d, r, after = error(q_fused)
        s = np.sqrt(np.diag(fused.covariance if tool_covariance is None else fused.covariance + tool_covariance))
        out["fused"] = {
            "after_mm_deg": after,
            "sigma_mm_deg": [round(float(np.linalg.norm(s[:3])), 4), round(float(np.linalg.norm(s[3:])), 5)],
            "look_weight_position_rotation": [
                round(float(np.mean(fused.look_weight[:3])), 3),
                round(float(np.mean(fused.look_weight[3:])), 3),
            ],
            "agree": fused.agree,
            "message": fused.message,
            "within_3_sigma": bool(
                np.linalg.norm(d) <= 3 * np.linalg.norm(s[:3]) and np.linalg.norm(r) <= 3 * np.linalg.norm(s[3:])
            ),
        }
    return out
