"""The calibration workflow without a window, against the simulated test bed: picks, undo and
redo, the solve, the end-effector displacement against the truth, the stored correction."""

from calib_core.calibration.look_solving import calibrate
from calib_core.calibration.correction_from_look import StoreLook
from calib_core.calibration.commands import SetPixel
from calib_core.calibration.commands import SetEnabled
from calib_core.calibration.commands import DeletePair
from calib_core.calibration.commands import ClearPairs
from calib_core.calibration.commands import AddPoint3D
import numpy as np
import pytest

from calib_core.calibration.errors import CalibrationError
from calib_core.calibration.session import CalibrationSession
from calib_core.camera.projection import project
from calib_core.frames import apply, invert, pose_difference
from calib_core.robot import solve_ik
from calib_core.solver import SolveStatus
from videocal_sim.test_bed import TestBed
from videocal_sim.true_robot import RobotErrors

FEATURES = [
    "plate_top_left",
    "plate_top_right",
    "plate_bottom_left",
    "plate_bottom_right",
    "pin_tip",
    "boss_top_left",
    "boss_top_right",
    "boss_bottom_left",
    "boss_bottom_right",
]


@pytest.fixture(scope="module")
def bed():
    errors = RobotErrors.typical(0)
    # No hand-eye error here: with the modelled mounting the camera tells the TCP exactly (the hand-eye calibration
    # measures it).
    errors = RobotErrors(errors.joint_offsets_deg, errors.link_errors_mm, errors.base_xyz_mm, errors.base_rpy_deg)
    return TestBed.create(errors=errors)


def _pick_all(session, bed, q, names=FEATURES, noise_px=0.2, seed=0):
    rng = np.random.default_rng(seed)
    fx = bed.workcell.component("oru_1_fixture")
    cam_true = bed.true_cam2world(q)
    for name in names:
        p_world = apply(fx.item2world, fx.features[name])
        session.undo.push(AddPoint3D(session.pairs, "oru_1_fixture", name, p_world, target=session.target))
        pixel = project(apply(invert(cam_true), p_world[None]), bed.intrinsics)[0] + rng.normal(0, noise_px, 2)
        session.undo.push(SetPixel(session.pairs, None, pixel))


def _look_at_the_approach(bed, noise_px=0.2):
    """The paper's task location, a session whose picks at its approach (``noise_px`` of noise) are solved, and the
    look."""
    task = bed.workcell.task("oru_1_grasp")
    q_app = solve_ik(bed.model_robot, task.approach2base, bed.workcell.home_joints_deg).q_deg
    s = CalibrationSession()
    s.set_target("oru_1_fixture")
    _pick_all(s, bed, q_app, noise_px=noise_px)
    return task, s, _calibrate(s, bed, q_app)


def _calibrate(session, bed, q):
    fx = bed.workcell.component("oru_1_fixture")
    return calibrate(session, bed.intrinsics, fx.item2world, bed.model_cam2world(q), bed.model_robot.fk(q, "tcp"), q)


def test_estimated_displacement_matches_the_truth(bed):
    q = solve_ik(bed.model_robot, bed.workcell.task("oru_1_grasp").approach2base, bed.workcell.home_joints_deg).q_deg
    s = CalibrationSession()
    s.set_target("oru_1_fixture")
    _pick_all(s, bed, q)
    est = _calibrate(s, bed, q)
    assert est.solution.status is SolveStatus.OK
    d_true, r_true = pose_difference(bed.true_robot.fk(q), bed.model_robot.fk(q))
    assert np.linalg.norm(d_true) > 3.0  # the model really is off
    # Within the reported uncertainty (a 0.2 px pick noise on a 160 x 120 mm plate: tenths of a mm).
    assert np.all(np.abs(est.displacement_mm - d_true) < 4 * est.std_displacement_mm + 0.05)
    assert np.all(np.abs(est.rotation_deg - r_true) < 4 * est.std_rotation_deg + 0.005)
    assert np.all(est.std_displacement_mm > 0) and np.all(est.std_displacement_mm < 1.0)


def test_stored_correction_brings_the_real_tool_to_the_target(bed):
    task, s, _ = _look_at_the_approach(bed, noise_px=0.0)
    q_app = s.result.context.joints_deg
    s.undo.push(StoreLook(s, task.name))
    # Uncorrected: the real tool misses the grasp by millimetres; corrected: by far less.
    q_plain = solve_ik(bed.model_robot, task.tcp2base, q_app).q_deg
    miss_plain = np.linalg.norm(pose_difference(bed.true_robot.fk(q_plain), task.tcp2base)[0])
    target = s.corrections.corrected_target(task.name, task.tcp2base)
    q_corr = solve_ik(bed.model_robot, target, q_plain).q_deg
    miss_corr = np.linalg.norm(pose_difference(bed.true_robot.fk(q_corr), task.tcp2base)[0])
    assert miss_plain > 3.0
    # The correction is measured at the approach pose (200 mm back), where the camera sees the fixture; the joints
    # change on the way to the grasp, and with them the model error: about 1 mm is left of 8.
    assert miss_corr < 1.5 and miss_corr < miss_plain / 5


def test_undo_redo_and_workflow_errors(bed):
    s = CalibrationSession()
    s.set_target("oru_1_fixture")
    with pytest.raises(CalibrationError, match="pick the point on the model"):
        s.undo.push(SetPixel(s.pairs, None, (10, 10)))
    n = s.undo.push(AddPoint3D(s.pairs, "oru_1_fixture", "pin_tip", (1.0, 2.0, 3.0), target=s.target)).number
    with pytest.raises(CalibrationError, match=f"pair {n} still needs its 2D point"):
        s.undo.push(AddPoint3D(s.pairs, "oru_1_fixture", "plate_top_left", (0, 0, 0), target=s.target))
    s.undo.push(SetPixel(s.pairs, None, (5.0, 6.0)))
    with pytest.raises(CalibrationError, match="pick on the target object 'oru_1_fixture'"):
        s.undo.push(AddPoint3D(s.pairs, "rack_1", None, (0, 0, 0), target=s.target))
    assert s.pairs.get(n).pixel == (5.0, 6.0)
    s.undo.push(SetEnabled(s.pairs, n, False))
    assert s.pairs.usable() == []
    assert s.undo.undo() == f"Disable pair {n}"
    assert s.pairs.get(n).enabled
    s.undo.push(DeletePair(s.pairs, n))
    assert len(s.pairs) == 0
    s.undo.undo()
    assert len(s.pairs) == 1 and s.pairs.get(n).pixel == (5.0, 6.0)
    s.undo.undo()  # the 2D pick
    assert s.pairs.get(n).pixel is None
    s.undo.redo()
    assert s.pairs.get(n).pixel == (5.0, 6.0)
    s.undo.push(ClearPairs(s.pairs))
    assert len(s.pairs) == 0
    s.undo.undo()
    assert len(s.pairs) == 1
    with pytest.raises(CalibrationError, match="1 complete pairs; calibrating needs 3"):
        calibrate(s, bed.intrinsics, np.eye(4), np.eye(4), np.eye(4))


def test_a_solve_is_one_undo_step_that_puts_the_previous_result_back(bed):
    """Calibrate is a command: undo shows the result it replaced (none before the first solve), redo the
    solve's own answer (not solved again), and the verdict is judged anew each time."""
    q = solve_ik(bed.model_robot, bed.workcell.task("oru_1_grasp").approach2base, bed.workcell.home_joints_deg).q_deg
    s = CalibrationSession()
    s.set_target("oru_1_fixture")
    _pick_all(s, bed, q, names=FEATURES[:5], seed=1)
    first = _calibrate(s, bed, q)
    assert s.undo.undo_label == "Calibrate (5 pairs)"
    _pick_all(s, bed, q, names=FEATURES[5:], seed=2)
    second = _calibrate(s, bed, q)
    assert s.result.estimate is second and s.result.solved_numbers == list(range(1, 10))
    changes = []
    s.result.changed.connect(lambda: changes.append(s.result.estimate))
    assert s.undo.undo() == "Calibrate (9 pairs)"
    assert s.result.estimate is first and s.result.solved_numbers == [1, 2, 3, 4, 5] and changes == [first]
    assert (
        s.stale_reason is not None and "6, 7, 8, 9" in s.stale_reason
    )  # the first answer, told apart from the pairs on screen
    s.undo.redo()
    assert s.result.estimate is second and s.result.verdict is not None and s.stale_reason is None
    for _ in range(9):  # the second solve and the second look's four pairs (3D and 2D each)
        s.undo.undo()
    assert s.undo.undo_label == "Calibrate (5 pairs)"
    s.undo.undo()
    assert s.result.estimate is None and s.result.verdict is None and s.result.solved_numbers == []


def test_listeners_hear_every_change():
    s = CalibrationSession()
    events = []
    s.pairs.changed.connect(lambda event, number: events.append((event, number)))
    s.undo.push(AddPoint3D(s.pairs, "a", None, (0, 0, 1), target=s.target))
    s.undo.push(SetPixel(s.pairs, None, (1, 2)))
    s.undo.undo()
    s.undo.undo()
    assert events == [("added", 1), ("changed", 1), ("changed", 1), ("removed", 1)]


def test_a_look_weighed_against_a_calibrated_model_stores_the_fused_or_asks(bed):
    """With a calibrated model's prior: a look that agrees is stored fused (its displacement pulled
    toward the model's, sigmas smaller); one that disagrees needs a confirmation, then is stored alone
    with the reason kept."""
    from calib_core.calibration.look_fusion import fuse_look
    from calib_core.calibration.errors import ConfirmationNeeded

    task, s, look = _look_at_the_approach(bed)
    sigma = np.sqrt(np.diag(look.covariance))
    agreeing = fuse_look(look, np.diag(np.r_[look.displacement_mm, look.rotation_deg] ** 2 + sigma**2))
    assert agreeing.agree
    c = s.undo.push(StoreLook(s, task.name, fused=agreeing)).correction
    assert np.allclose(c.displacement_mm, agreeing.displacement_mm) and np.allclose(c.delta_base, agreeing.delta_base)
    assert (
        np.all(c.std_displacement_mm < look.std_displacement_mm)
        and "look and model agree" in c.source
        and not c.confirmation
    )
    s.corrections.remove_last(task.name)
    tight = fuse_look(
        look, np.diag([1e-6] * 3 + [1e-8] * 3)
    )  # a model "certain" the TCP is where it says: millimetres away
    assert not tight.agree
    with pytest.raises(ConfirmationNeeded, match="sigma from the calibrated model"):
        s.undo.push(StoreLook(s, task.name, fused=tight))
    assert s.corrections.latest(task.name) is None  # nothing stored
    c = s.undo.push(StoreLook(s, task.name, fused=tight, confirmation="the operator checked the image")).correction
    assert np.allclose(c.displacement_mm, look.displacement_mm) and "the look alone" in c.source and c.confirmation


def test_a_look_stored_alone_carries_the_measured_tool_s_uncertainty(bed):
    """A look reaches the TCP through the measured tool: its covariance (here 0.05 mm and 0.01 deg per
    axis) is in the stored 1-sigma when no calibrated model is weighed against the look."""
    task, s, look = _look_at_the_approach(bed)
    tool = np.diag([0.05**2] * 3 + [0.01**2] * 3)
    c = s.undo.push(StoreLook(s, task.name, tool_covariance=tool)).correction
    assert np.allclose(c.std_displacement_mm, np.sqrt(look.std_displacement_mm**2 + 0.05**2))
    assert np.allclose(c.std_rotation_deg, np.sqrt(look.std_rotation_deg**2 + 0.01**2))
    assert "measured tool" in c.source and np.allclose(c.displacement_mm, look.displacement_mm)
