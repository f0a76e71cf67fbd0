"""The demo's report: what the scripted operator did and met, and the corrected task location scored against the
test bed's truth (the only place the demo reads it, besides the simulated operator's eyes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from calib_core.frames import pose_difference
from calib_core.robot import solve_ik
from videocal_sim.demo_site import camera_url


@dataclass
class OperatorLog:
    """What the scripted operator recorded on its way: one entry per look where a list is per look."""

    shots: list[str] = field(default_factory=list)  # the screenshots' file names, in order
    skipped: list[str] = field(default_factory=list)  # features not picked, and why
    refined_away: list[str] = field(default_factory=list)  # corners where the sub-pixel refinement left the corner
    confirmed: list[str] = field(default_factory=list)  # moves confirmed in the overview (large joint changes)
    go_to_settled_s: list[float] = field(default_factory=list)  # Go pressed -> a frame the core accepts for picks
    look_s: list[float] = field(default_factory=list)  # a settled frame -> the correction stored, screenshots left out
    look_actions: list[int] = field(default_factory=list)  # the operator's clicks, keys and zooms in each look
    proposals_s: list[float] = field(default_factory=list)  # Find points pressed -> its proposals shown, each look


def demo_report(
    *,
    workcell: Path,
    method: str,
    look: str,
    site_kind: str,
    link_delay_ms: float,
    wb,
    bed,
    log: OperatorLog,
    first,
    q_first: np.ndarray,
    q_measured: np.ndarray,
) -> dict:
    """The report as ``report.json`` holds it: ``wb`` the workbench after the second look, the robot at the corrected
    task location; ``first`` the first look's estimate, made at joints ``q_first`` (deg); the second made at
    ``q_measured``. Distances mm, angles deg."""
    task = wb.task
    r = wb.session.result.estimate
    d_true, r_true = pose_difference(bed.true_robot.fk(q_measured), bed.model_robot.fk(q_measured))
    d_first, r_first = pose_difference(bed.true_robot.fk(q_first), bed.model_robot.fk(q_first))
    miss_d, miss_r = pose_difference(bed.true_robot.fk(wb.joints_deg), task.tcp2base)
    q_plain = solve_ik(wb.robot, task.tcp2base, wb.joints_deg).q_deg
    plain_d, plain_r = pose_difference(bed.true_robot.fk(q_plain), task.tcp2base)
    return {
        "workcell": str(Path(workcell).resolve()),
        "robot_joints": wb.robot.n_joints,
        "task_location": task.name,
        "method": method,
        "site": wb.site.description,
        "camera_look": look,
        "settled_frame_to_stored_s": [round(v, 2) for v in log.look_s],
        "operator_actions_per_look": log.look_actions,
        "find_points_proposals_s": [round(v, 2) for v in log.proposals_s],
        "link": {
            "one_way_ms": link_delay_ms,
            "measured_one_way_s": getattr(wb.link, "delay_s", None),
            "go_to_settled_frame_s": [round(v, 2) for v in log.go_to_settled_s],
        },
        "connectors": {"controller": wb.link.url, "camera": camera_url(site_kind)},
        "target": wb.session.target,
        "features_skipped": log.skipped,
        "subpixel_refinement_refused": log.refined_away,
        "moves_confirmed": log.confirmed,
        "status": r.solution.status.value,
        "pairs": len(wb.session.pairs.usable()) if r.solution.method == "points" else 0,
        "edge_samples": len(r.solution.residuals_px) if r.solution.method == "edges" else 0,
        "rms_px": r.solution.rms_px,
        "estimated_displacement": {"d_mm": r.displacement_mm.tolist(), "rotation_deg": r.rotation_deg.tolist()},
        "std": {"d_mm": r.std_displacement_mm.tolist(), "rotation_deg": r.std_rotation_deg.tolist()},
        "true_displacement": {"d_mm": d_true.tolist(), "rotation_deg": r_true.tolist()},
        "first_look": {
            "estimated_displacement": {
                "d_mm": first.displacement_mm.tolist(),
                "rotation_deg": first.rotation_deg.tolist(),
            },
            "true_displacement": {"d_mm": d_first.tolist(), "rotation_deg": r_first.tolist()},
            "rms_px": first.solution.rms_px,
        },
        "uncorrected_tcp_error_mm": float(np.linalg.norm(plain_d)),
        "uncorrected_tcp_error_deg": float(np.linalg.norm(plain_r)),
        "corrected_tcp_error_mm": float(np.linalg.norm(miss_d)),
        "corrected_tcp_error_deg": float(np.linalg.norm(miss_r)),
        "hand_eye": "exact",
        "estimate_within_3_sigma": bool(np.all(np.abs(r.displacement_mm - d_true) <= 3 * r.std_displacement_mm)),
        "screenshots": log.shots,
        "note": "the true robot has typical joint, link and base errors and the modelled camera mounting (hand_eye "
        "exact: a hand-eye calibration takes the robot's kinematics as exact, so with these errors it cannot be better "
        "than they are); the correction is measured at the task location, then again from the corrected location, and "
        "the second one is stored last",
    }
