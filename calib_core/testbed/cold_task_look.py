"""The last step of the cold cell's chain: one look at a task location on the calibrated model.

The calibrated robot (its joints, camera and tool) goes to the task's approach; Find points' edge
refinement measures the task's component through the calibrated intrinsics (Calibrate on edges); the
end effector's displacement there is the correction (``Δ``, :mod:`calib_core.calibration.end_effector`);
the robot is commanded to ``Δ^-1 . target`` through the calibrated model. The truth places the robot
and renders the frame, and scores where the true TCP ends up: nothing else reads it.
"""

from __future__ import annotations

import numpy as np

from calib_core.calibration.end_effector import end_effector_from_solution
from calib_core.frames import invert, pose_difference
from calib_core.render.model_view import ModelView
from calib_core.robot import solve_ik
from calib_core.robot.visuals import RobotVisuals
from calib_core.testbed.sim_camera import SimulatedCamera
from calib_core.vision.edge_solution import edge_solution
from calib_core.vision.find_points import find_points


def look_at_task(bed, robot, intrinsics, task_name: str | None = None, seed: int = 0, model_covariance=None) -> dict:
    """Figures of one look at ``task_name`` (default: the cell's first task) with the calibrated
    ``robot`` and ``intrinsics``: the TCP's true error at the task commanded through the calibrated
    model without the look and with it, the look's own 1-sigma, and whether the error is within 3 sigma.
    ``model_covariance(q_deg)``: the calibrated model's TCP covariance (6, 6: mm, deg) at joints; with
    it the look is also fused with the model (:mod:`calib_core.calibration.look_fusion`) and scored."""
    cell = bed.workcell
    task = cell.task(task_name) if task_name else next(iter(cell.task_locations.values()))
    item = cell.component(task.component)
    home = np.asarray(cell.home_joints_deg, dtype=float)
    q_approach = solve_ik(robot, task.approach2base, home).q_deg
    bed.joints_deg = q_approach
    camera = SimulatedCamera(bed.intrinsics, bed.true_scene, bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed + 7)
    view = ModelView(intrinsics)
    try:
        image = camera.read().image
        cam2world_model = robot.fk(q_approach, "camera")
        obj2cam_model = invert(cam2world_model) @ item.item2world
        expected = view.of(list(cell.components) + RobotVisuals.from_robot(robot).scene_items(q_approach), item.item2world)
        found = find_points(image, intrinsics, item, obj2cam_model, expected=expected)
    finally:
        camera.close()
        view.close()
    out = {"task": task.name, "found": bool(found.edges is not None and found.edges.settled), "message": found.message}
    q_plain = solve_ik(robot, task.tcp2base, q_approach).q_deg
    d, r = pose_difference(bed.true_robot.fk(q_plain, "tcp"), task.tcp2base)
    out["calibrated_model_only_mm_deg"] = [round(float(np.linalg.norm(d)), 4), round(float(np.linalg.norm(r)), 5)]
    if not out["found"]:
        return out
    solution = edge_solution(found.edges, intrinsics)
    estimate = end_effector_from_solution(solution, item.item2world, cam2world_model, robot.fk(q_approach, "tcp"))
    q_task = solve_ik(robot, invert(estimate.delta_base) @ task.tcp2base, q_approach).q_deg
    d, r = pose_difference(bed.true_robot.fk(q_task, "tcp"), task.tcp2base)
    sigma_mm = float(np.linalg.norm(estimate.std_displacement_mm))
    sigma_deg = float(np.linalg.norm(estimate.std_rotation_deg))
    out.update({
        "after_look_mm_deg": [round(float(np.linalg.norm(d)), 4), round(float(np.linalg.norm(r)), 5)],
        "look_sigma_mm_deg": [round(sigma_mm, 4), round(sigma_deg, 5)],
        "look_displacement_mm": [round(float(v), 4) for v in estimate.displacement_mm],
        "within_3_sigma": bool(np.linalg.norm(d) <= 3 * sigma_mm and np.linalg.norm(r) <= 3 * sigma_deg),
    })
    if model_covariance is not None and estimate.covariance is not None:
        from calib_core.calibration.look_fusion import fuse_look

        fused = fuse_look(estimate, model_covariance(q_approach))
        q_fused = solve_ik(robot, invert(fused.delta_base) @ task.tcp2base, q_approach).q_deg
        d, r = pose_difference(bed.true_robot.fk(q_fused, "tcp"), task.tcp2base)
        s = np.sqrt(np.diag(fused.covariance))
        out["fused"] = {
            "after_mm_deg": [round(float(np.linalg.norm(d)), 4), round(float(np.linalg.norm(r)), 5)],
            "sigma_mm_deg": [round(float(np.linalg.norm(s[:3])), 4), round(float(np.linalg.norm(s[3:])), 5)],
            "look_weight_position_rotation": [round(float(np.mean(fused.look_weight[:3])), 3), round(float(np.mean(fused.look_weight[3:])), 3)],
            "agree": fused.agree, "message": fused.message,
            "within_3_sigma": bool(np.linalg.norm(d) <= 3 * np.linalg.norm(s[:3]) and np.linalg.norm(r) <= 3 * np.linalg.norm(s[3:])),
        }
    return out
