"""The move preview: the joint path the controller follows, closeness to a singularity (checked
against a finite-difference Jacobian), collisions with a placed obstacle, and what needs a
confirmation."""

import numpy as np
import trimesh

from calib_core.frames import make_transform
from calib_core.operator.cell import Cell
from calib_core.operator.move_preview import REACH_SCALE_MM, STEP_DEG, joint_path, preview_move, scaled_min_singular
from calib_core.robot.collision import CollisionWorld
from calib_core.scene import SceneItem
from calib_core.workcell.safety import SafetyLimits


def test_the_path_is_the_joint_space_line_in_small_steps():
    path = joint_path([0.0, 10.0], [9.0, 10.0])
    assert path.shape == (6, 2) and np.allclose(path[0], [0, 10]) and np.allclose(path[-1], [9, 10])
    assert np.max(np.abs(np.diff(path, axis=0))) <= STEP_DEG + 1e-12
    assert joint_path([1.0], [1.0]).shape == (2, 1)


def test_the_singularity_measure_matches_a_finite_difference_jacobian():
    robot = Cell.open().robot
    q = np.array([10.0, -20.0, 30.0, 15.0, 25.0, -5.0])
    h = 1e-4  # deg
    cols = []
    for j in range(robot.n_joints):
        dq = np.zeros(robot.n_joints)
        dq[j] = h
        a, b = robot.fk(q + dq, "tcp"), robot.fk(q - dq, "tcp")
        v = (a[:3, 3] - b[:3, 3]) / (2 * np.radians(h)) / REACH_SCALE_MM
        dR = a[:3, :3] @ b[:3, :3].T
        w = np.array([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / 2 / (2 * np.radians(h))
        cols.append(np.concatenate([v, w]))
    expected = np.linalg.svd(np.array(cols).T, compute_uv=False)[-1]
    assert abs(scaled_min_singular(robot, q) - expected) < 1e-5
    q[4] = 0.0  # the wrist straight: joints 4 and 6 turn about one axis
    assert scaled_min_singular(robot, q) < 1e-9


def test_a_box_in_the_way_blocks_the_move_and_a_large_change_needs_a_confirmation():
    cell = Cell.open()
    robot, home = cell.robot, cell.home_joints
    goal = np.array(home, dtype=float)
    goal[0] += 40.0
    goal[4] += 30.0  # off the wrist singularity of home
    halfway = robot.fk((np.asarray(home) + goal) / 2, "flange")[:3, 3]
    crate = SceneItem("crate", trimesh.creation.box((120.0, 120.0, 120.0)), make_transform(np.eye(3), halfway))
    free = CollisionWorld(robot, list(cell.workcell.components), home)
    blocked = CollisionWorld(robot, list(cell.workcell.components) + [crate], home)
    assert not any(c.b == "cell/crate" for q in joint_path(home, goal) for c in free.check(q))
    p = preview_move(robot, blocked, home, goal, "past the crate", SafetyLimits())
    assert p.blocked and "crate" in p.problems[0] and 0 < p.contact_step < len(p.path_deg) - 1
    ok = preview_move(robot, free, home, goal, "around", SafetyLimits())
    assert not ok.blocked and ok.needs_confirmation and "joint_1 +40.0 deg" in ok.confirm_reasons[0]
    assert not preview_move(
        robot, free, home, goal, "around", SafetyLimits(confirm_joint_change_deg=45.0)
    ).needs_confirmation
    near = preview_move(robot, free, home, home + np.array([1.0, 0, 0, 0, 0, 0]), "a nudge", SafetyLimits())
    assert any("near a singularity" in w for w in near.warnings)  # home has the wrist straight
