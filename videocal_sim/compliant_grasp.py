"""The gripper closed on a fixture pin in the simulated cell: compliance puts the true TCP on the pin.

What the physical cell does by itself (the fingers centre on the pin, the controller in compliance lets
the joints follow) is done here by inverse kinematics on the true robot: the commanded joints whose
true TCP is the pin's grasp, within the compliance's own error. Only the simulation uses the truth.
"""

from __future__ import annotations

import numpy as np

from calib_core.frames import concat, invert, make_transform
from calib_core.robot import solve_ik
from videocal_sim.sim_camera import SimulatedCamera
from videocal_sim.test_bed import TestBed

COMPLIANCE_MM = 0.02
"""How far from the pin's axis the fingers leave the TCP (a centring gripper on a ground pin)."""


def grasp_joints(bed: TestBed, tcp2base: np.ndarray, seed: int = 0, component: str | None = None) -> np.ndarray:
    """The commanded joints (deg) the controller reports with the gripper closed on the pin whose
    grasp the workcell file puts at ``tcp2base`` (4, 4) mm: the true TCP on the pin where it truly
    stands (``component``'s true placement in the test bed, when it is moved from the file's, as the
    cold cell's survey moves them), to within :data:`COMPLIANCE_MM`."""
    rng = np.random.default_rng(seed)
    off = rng.normal(0.0, 1.0, 3)
    off *= COMPLIANCE_MM * rng.uniform() / max(np.linalg.norm(off), 1e-9)
    surveyed = np.asarray(tcp2base, dtype=float)
    on_pin = surveyed
    if component is not None and bed.true_components is not None:
        true_item = next((c for c in bed.true_components if c.name == component), None)
        if true_item is not None:
            on_pin = concat(surveyed, invert(bed.workcell.component(component).item2world), true_item.item2world)
    target = concat(on_pin, make_transform(np.eye(3), off))
    true = bed.true_robot
    # TrueRobot.fk(q) = base_true2base_model . robot.fk(q + offsets): solve on its robot, then undo the offsets.
    start = np.asarray(bed.workcell.home_joints_deg, dtype=float)
    seed_q = solve_ik(bed.model_robot, surveyed, start).q_deg
    q_true = solve_ik(true.robot, concat(target, invert(true.base_true2base_model)), seed_q + true.joint_offsets).q_deg
    return q_true - true.joint_offsets


def grasp_frame(bed: TestBed, q_commanded_deg: np.ndarray, seed: int = 0) -> np.ndarray:
    """The camera's frame (h, w, 3) uint8 with the robot at ``q_commanded_deg`` (the gripper closed on
    a pin): what an operator's camera shows while the controller holds the grasp."""
    bed.joints_deg = np.asarray(q_commanded_deg, dtype=float)
    camera = SimulatedCamera(
        bed.intrinsics, bed.true_scene, bed.true_cam2world, lambda: bed.joints_deg.copy(), seed=seed + 11
    )
    try:
        return camera.read().image
    finally:
        camera.close()
