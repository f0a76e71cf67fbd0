"""The robot calibration on the cold cell, start to end, as ``videocal calibrate-robot sim``, the bench
and the tests run it: plan with the nominal model, view and detect with the true camera, calibrate
the intrinsics from the same views, identify; then the score against the truth, the one place here
that reads it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation

from calib_core.camera.intrinsics_io import load_intrinsics
from calib_core.frames import concat, invert, pose_difference
from calib_core.robot_calibration.calibrated_robot import RobotCalibration
from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM
from calib_core.robot_calibration.identify_robot import identify_robot
from calib_core.robot_calibration.pose_planner import PosePlan, plan_poses
from calib_core.robot_calibration.camera_to_tool import CameraToTool, Grasp, camera_to_tool, with_tool
from calib_core.robot_calibration.cell_views import cell_view_joints
from calib_core.robot_calibration.grasp_view import GraspNotSeenError, see_grasp
from videocal_sim.compliant_grasp import grasp_frame, grasp_joints
from videocal_sim.robot_calibration_views import simulated_cell_frames, simulated_pose_views
from videocal_sim.cold_cell import cold_test_bed
from calib_core.vision.board import DEFAULT_SPEC, parse_board
from calib_core.vision.board_placement import board_in_cell
from calib_core.vision.intrinsics_calibration import IntrinsicsCalibration, calibrate_intrinsics

HELD_OUT = 20
"""Planned poses not used for the calibration: the truth is compared there."""


@dataclass(frozen=True)
class ColdRun:
    """``result`` the identification; ``robot`` the calibrated robot with its TCP from the grasps
    (``tool``; the identification's robot when there were none); ``score`` against the truth."""

    result: RobotCalibration
    intrinsics: IntrinsicsCalibration
    plan: PosePlan
    rejected: list[str]
    score: dict
    nominal_robot: object
    tool: CameraToTool | None = None
    robot: object = None
    board_views: int = 0
    cell_views: int = 0


def calibrate_cold_cell(
    views: int = 40,
    seed: int = 0,
    *,
    cell_views_per_task: int = 3,
    grasps: bool = True,
    grasp_tasks: list[str] | None = None,
    with_intrinsics: bool = True,
    seen_grasps: bool = True,
    progress=None,
    say=lambda text: None,
) -> ColdRun:
    """``views`` board views and ``cell_views_per_task`` views of each task location's component
    (surveyed features: they tie the robot to the cell; 0 leaves the base unidentified); with
    ``grasps``, the gripper closed on each task location's fixture (``grasp_tasks``: only these) gives
    the TCP from the camera; ``seen_grasps``: the camera's frame at each grasp measures it
    (:mod:`calib_core.robot_calibration.grasp_view`), else the survey through the calibrated robot."""
    bed, truth = cold_test_bed(seed=seed)
    nominal = load_intrinsics(bed.workcell.intrinsics_path)
    spec = parse_board(DEFAULT_SPEC)
    board2base = board_in_cell(spec, bed.workcell, bed.model_robot)
    say(f"planning {views} poses...")
    wanted = views + HELD_OUT
    plan = plan_poses(
        bed.model_robot,
        nominal,
        spec,
        board2base,
        wanted,
        start_deg=bed.workcell.home_joints_deg,
        candidates=min(160, 3 * wanted),
        seed=seed,
    )
    calibration_q, held_out = plan.joints_deg[:views], plan.joints_deg[views:]
    board_views, pose_views, rejected = simulated_pose_views(
        bed, spec, board2base, calibration_q, seed=seed, progress=progress
    )
    intrinsics = calibrate_intrinsics(board_views, spec)
    say(f"intrinsics: RMS {intrinsics.rms_px:.3f} px from {len(board_views)} views")
    cell_frames = []
    if cell_views_per_task:
        from calib_core.robot.collision import CollisionWorld

        world = CollisionWorld(bed.model_robot, list(bed.workcell.components), bed.workcell.home_joints_deg)
        targets = cell_view_joints(
            bed.model_robot, bed.workcell, intrinsics.intrinsics, cell_views_per_task, seed, collisions=world
        )
        say(f"locating surveyed features in {len(targets)} views...")
        cell_frames = simulated_cell_frames(bed, targets, seed=seed)
    say("identifying...")
    identified = identify_robot(
        bed.model_robot,
        intrinsics.intrinsics,
        bed.workcell,
        pose_views,
        cell_frames,
        visuals=bed.visuals_for_model(),
        with_intrinsics=with_intrinsics,
    )
    result = identified.result
    robot, tool = result.robot, None
    if grasps:
        tasks = [t for t in bed.workcell.task_locations.values() if grasp_tasks is None or t.name in grasp_tasks]
        done = []
        for k, t in enumerate(tasks):
            q = grasp_joints(bed, t.tcp2base, seed + k, t.component)
            seen = None
            if seen_grasps:
                try:
                    seen = see_grasp(grasp_frame(bed, q, seed + k), result.intrinsics, result.robot, bed.workcell, t, q)
                except GraspNotSeenError as e:
                    say(f"{e}: that grasp is taken through the calibrated robot and the survey")
            done.append(Grasp(t.name, q, t.tcp2base, seen))
        tool = camera_to_tool(
            result.robot,
            done,
            placement_sigma_mm=SURVEY_SIGMA_MM,
            camera_covariance=lambda q: result.pose_covariance(q),
        )
        robot = with_tool(result.robot, tool.tcp2cam)
        say(
            f"camera to tool from {len(tool.per_grasp)} grasps, {tool.seen_grasps} seen (spread {tool.spread_mm:.3f} "
            f"mm, {tool.spread_deg:.4f} deg)"
        )
    score = score_against_truth(result, bed, truth, held_out, board2base, robot)
    score["parameters_against_truth"] = parameters_against_truth(result, bed, identified.views, intrinsics.intrinsics)
    return ColdRun(
        result,
        intrinsics,
        plan,
        rejected,
        score,
        bed.model_robot,
        tool,
        robot,
        identified.board_views,
        identified.cell_views,
    )


def score_against_truth(
    result: RobotCalibration, bed, truth, held_out: list[np.ndarray], board2base_true: np.ndarray, robot=None
) -> dict:
    """How far the calibrated model is from the test bed's truth at ``held_out`` poses: the camera and
    the TCP relative to the board (what board views determine) and in the base frame, RMS mm and deg;
    the intrinsics' differences. ``robot``: the calibrated robot to score (default the
    identification's). Only for scoring."""
    robot = robot or result.robot

    def rms(pairs):
        a = np.array(pairs)
        return [round(float(np.sqrt(np.mean(a[:, 0] ** 2))), 4), round(float(np.sqrt(np.mean(a[:, 1] ** 2))), 5)]

    out = {}
    if held_out and result.board2base is not None:
        for frame in ("camera", "tcp"):
            rel, base, nominal = [], [], []
            for q in held_out:
                est, tru = robot.fk(q, frame), bed.true_robot.fk(q, frame)
                d, r = pose_difference(invert(result.board2base) @ est, invert(board2base_true) @ tru)
                rel.append((np.linalg.norm(d), np.linalg.norm(r)))
                d, r = pose_difference(est, tru)
                base.append((np.linalg.norm(d), np.linalg.norm(r)))
                d, r = pose_difference(bed.model_robot.fk(q, frame), tru)
                nominal.append((np.linalg.norm(d), np.linalg.norm(r)))
            out[f"{frame}_in_board_frame_mm_deg"] = rms(rel)
            if frame == "camera":
                out["camera_in_base_frame_within_3_sigma"] = _within_3_sigma(result, bed, held_out)
            out[f"{frame}_in_base_frame_mm_deg"] = rms(base)
            out[f"{frame}_nominal_model_mm_deg"] = rms(nominal)
        out["held_out_poses"] = len(held_out)
    t, i = truth.intrinsics, result.intrinsics
    out["intrinsics_error_px"] = {
        "fu": round(i.fu - t.fu, 3),
        "fv": round(i.fv - t.fv, 3),
        "cx": round(i.cx - t.cx, 3),
        "cy": round(i.cy - t.cy, 3),
    }
    return out


def _within_3_sigma(result: RobotCalibration, bed, held_out: list[np.ndarray]) -> float:
    """The share of held-out poses whose camera pose error (base frame) lies within the 3-sigma
    ellipsoid of its propagated covariance (chi-square with 6 degrees of freedom at 99.73 %)."""
    from scipy.stats import chi2

    limit = chi2.ppf(0.9973, 6)
    inside = 0
    for q in held_out:
        est, tru = result.robot.fk(q, "camera"), bed.true_robot.fk(q, "camera")
        d = np.r_[tru[:3, 3] - est[:3, 3], 1000.0 * Rotation.from_matrix(tru[:3, :3] @ est[:3, :3].T).as_rotvec()]
        cov = result.pose_covariance(q)
        inside += float(d @ np.linalg.pinv(cov) @ d) <= limit
    return round(inside / max(len(held_out), 1), 3)


def truth_in_model_parameters(bed) -> np.ndarray:
    """The test bed's true robot in the error model's own parameters (mm, mrad): each joint's true
    placement with its zero offset folded in, the base's error on the first joint, the camera's."""
    from calib_core.robot.model import _to_mm
    from calib_core.robot_calibration.parameters import CorrectedRobot, delta_of

    nominal, true = bed.model_robot, bed.true_robot
    layout = CorrectedRobot(nominal).layout
    p = np.zeros(layout.size)
    root2base = invert(nominal.base2root)
    # Each joint's zero offset is its motion at q = offset after the placement: liMi at the offsets.
    data = nominal.model.createData()
    pin.forwardKinematics(nominal.model, data, nominal.configuration(true.joint_offsets))
    for j in range(1, nominal.model.njoints):
        P = _to_mm(nominal.model.jointPlacements[j])
        T = _to_mm(true.robot.model.jointPlacements[j]) @ np.linalg.inv(P) @ _to_mm(data.liMi[j])
        if j == 1:  # the base's error is the first joint's: the survey is in the base frame
            T = concat(T, root2base, true.base_true2base_model, invert(root2base))
        p[layout.joint_block(j - 1)] = delta_of(T @ np.linalg.inv(P))
    Pc, Tc = nominal.frame_placement("camera"), true.robot.frame_placement("camera")
    p[layout.camera_block] = delta_of(Tc @ np.linalg.inv(Pc))
    return p


def parameters_against_truth(result: RobotCalibration, bed, views, intrinsics) -> dict:
    """The identified parameters against the truth mapped into the identified subset: with redundant
    parameters the fit puts the unidentified ones' share into the identified (to first order
    ``p_id + (J_id^+ J_unid) p_unid``, the board's placement a nuisance). ``within_3_sigma`` is the share
    of identified parameters within 3 of their sigmas of it."""
    from calib_core.robot_calibration.identification import SURVEY_SIGMA_MM, IdentificationProblem

    truth = truth_in_model_parameters(bed)
    with_intrinsics = len(result.names) > truth.size
    if with_intrinsics:  # the true camera as the corrections to the intrinsics the fit started from
        t = bed.intrinsics
        truth = np.r_[
            truth,
            t.fu - intrinsics.fu,
            t.fv - intrinsics.fv,
            t.cx - intrinsics.cx,
            t.cy - intrinsics.cy,
            1000.0 * (np.asarray(t.distortion[:4]) - np.asarray(intrinsics.distortion[:4])),
        ]
    problem = IdentificationProblem(
        result.nominal, intrinsics, views, result.camera_frame, with_intrinsics, SURVEY_SIGMA_MM
    )
    problem.board0 = result.board2base if result.board2base is not None else np.eye(4)
    ids, unid = result.observability.identified, result.observability.unidentified
    J, Jb = problem.jacobian(result.values, np.zeros(6), list(range(problem.size)))
    W = result.residual_weights[:, None]
    A = W * np.hstack([J[:, ids], Jb])
    absorbed = np.linalg.lstsq(A, W * J[:, unid], rcond=None)[0][: len(ids)] @ truth[unid]
    expected = truth[ids] + absorbed
    z = (result.values[ids] - expected) / result.sigmas[ids]
    return {
        "within_3_sigma": round(float(np.mean(np.abs(z) < 3.0)), 3),
        "rms_error_over_sigma": round(float(np.sqrt(np.mean(z**2))), 2),
        "worst": result.names[ids[int(np.argmax(np.abs(z)))]],
    }
