"""Every image pick bound to its frame and the robot's joints then: the 432 mm correction of a restored
session, picks while the robot moves, pairs from two poses, a link that drops, and plausibility."""

from calib_core.calibration.look_solving import calibrate
from calib_core.calibration.commands import SetPixel
from calib_core.calibration.commands import ClearPairs
from calib_core.calibration.commands import AddPoint3D
import numpy as np
import pytest

from calib_core.calibration.errors import CalibrationError, ConfirmationNeeded
from calib_core.calibration.look_place import LookNotAtTask
from calib_core.calibration.verdict import Verdict
from calib_core.frames import apply
from calib_core.operator.core import OperatorCore
from calib_core.operator.observations import NotSettledError
from tests.core.operator.perfect_operator import FEATURES, pick_all, task_joints
from tests.core.operator.still_robot import frame_now, sample, still_for
from videocal_sim.sim_site import simulated_cell


@pytest.fixture
def cell_and_site():
    return simulated_cell(image_scale=0.5)


def _picked_at_task(cell, site) -> tuple[OperatorCore, np.ndarray]:
    """A core whose pairs were picked (perfectly) on a still at the task location's approach."""
    core = OperatorCore(cell, site)
    q_task = task_joints(core)
    still_for(core, joints_deg=q_task)
    frame_now(core)
    pick_all(core, site.bed, q_task)
    return core, q_task


def test_a_restored_session_solves_with_the_joints_its_picks_were_made_at(cell_and_site, tmp_path):
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    q_task = task_joints(core)
    still_for(core, joints_deg=q_task)
    frame_now(core, index=7)
    pick_all(core, site.bed, q_task)
    stamps = {p.view for p in core.session.pairs}
    assert len(stamps) == 1 and next(iter(stamps)).frame_index == 7  # one still for the whole set
    np.testing.assert_allclose(next(iter(stamps)).joints_deg, q_task, atol=1e-9)
    at_task = core.picking.calibrate()
    assert core.session.result.verdict.verdict is Verdict.OK, core.session.result.verdict.text
    # The truth scores the estimate (nothing above read it): the measured camera pose is the real one.
    true_cam = site.bed.true_cam2world(q_task)
    assert np.linalg.norm(at_task.cam2world_measured[:3, 3] - true_cam[:3, 3]) < 0.01
    core.files.save_workspace(tmp_path / "w.json")
    core.files.release()  # quit (its window lets go of the file)
    # Quit, start again with the robot at home, restore, Calibrate: the same answer, not a 432 mm one.
    again = OperatorCore(cell, site)
    still_for(again, joints_deg=cell.home_joints)
    again.files.open_workspace(tmp_path / "w.json")
    restored = again.picking.calibrate()
    np.testing.assert_allclose(restored.displacement_mm, at_task.displacement_mm, atol=1e-9)
    np.testing.assert_allclose(again.session.result.context.joints_deg, q_task, atol=1e-9)
    assert np.linalg.norm(restored.displacement_mm) < 25.0
    # A new pick on a frame of the home pose joins pairs of the task pose: refused, naming them.
    frame_now(again, index=8)
    again.picking.pick_model_point(core.task.component, "pin_tip", (0.0, 0.0, 0.0))
    with pytest.raises(CalibrationError, match=r"pairs 1, 2, .* another pose"):
        again.picking.pick_image_point((10.0, 10.0))
    assert again.session.pairs.pending() is not None  # nothing was picked


def test_the_old_way_gives_an_implausible_result_that_needs_a_confirmation(cell_and_site):
    """The same pixels solved with the home joints (what the old code did) are refused as implausible."""
    cell, site = cell_and_site
    core, _ = _picked_at_task(cell, site)
    obj2world = core.workcell.component(core.session.target).item2world
    home = cell.home_joints
    result = calibrate(
        core.session, core.intrinsics, obj2world, core.robot.fk(home, "camera"), core.robot.fk(home, "tcp"), home
    )
    assert np.linalg.norm(result.displacement_mm) > 100.0
    verdict = core.session.result.verdict
    assert verdict.verdict is Verdict.IMPLAUSIBLE and "beyond the cell's stated model error of 25 mm" in verdict.text
    with pytest.raises(LookNotAtTask, match="from .*'s pose"):  # the home joints are not the task location's pose
        core.desk.store_correction()
    converted = "converted by a test: the look is the task's"
    with pytest.raises(ConfirmationNeeded) as refused:
        core.desk.store_correction(convert=converted)
    assert refused.value.reasons == verdict.reasons and core.session.corrections.latest(core.task.name) is None
    events = []
    core.log.event.connect(lambda kind, detail: events.append((kind, detail)))
    stored = core.desk.store_correction(convert=converted, confirmation="confirmed by a test: the cell was moved")
    assert stored.verdict == "implausible" and stored.confirmation == "confirmed by a test: the cell was moved"
    assert (
        "correction_confirmed",
        {"task": core.task.name, "verdict": "implausible", "confirmation": stored.confirmation},
    ) in events


def test_a_result_whose_pairs_changed_is_stale_and_cannot_be_stored(cell_and_site):
    cell, site = cell_and_site
    core, _ = _picked_at_task(cell, site)
    core.picking.calibrate()
    assert core.session.stale_reason is None
    core.picking.delete_pair(2)
    assert "pair 2 is no longer used" in core.session.stale_reason
    with pytest.raises(CalibrationError, match="from an earlier state"):
        core.desk.store_correction()
    core.undo()  # the pair is back as it was: the result is current again
    assert core.session.stale_reason is None
    core.session.undo.push(ClearPairs(core.session.pairs))
    assert "no longer used" in core.session.stale_reason
    assert core.observations.still is None  # no image point left: the still is let go


def test_a_frame_taken_while_the_robot_moves_is_refused_with_the_reason(cell_and_site):
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    t = still_for(core, seconds=1.0)
    q = np.array(core.joints_deg)
    for k in range(1, 11):  # joint 2 turns at 10 deg/s
        q[1] += 0.2
        sample(core, q, t + 0.02 * k)
    frame_now(core, t_s=t + 0.2)
    core.picking.pick_model_point(core.task.component, "pin_tip", (0.0, 0.0, 0.0))
    with pytest.raises(
        NotSettledError, match=rf"moving when the frame was taken \({core.robot.joint_names[1]} at 10.00 deg/s"
    ):
        core.picking.pick_image_point((10.0, 10.0))
    assert core.observations.still is None and core.session.pairs.pending() is not None
    # Still again for the settle time: the next frame is usable.
    end = still_for(core, seconds=0.4, joints_deg=q, start_s=t + 0.22)
    frame_now(core, t_s=end)
    core.picking.pick_image_point((10.0, 10.0))
    np.testing.assert_allclose(core.session.pairs.pairs()[0].view.joints_deg, q, atol=1e-9)


def test_a_link_that_drops_leaves_the_pose_unknown_until_a_fresh_sample(cell_and_site):
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    still_for(core)
    core.arm._on_link_state("down", "device lost")
    frame_now(core)
    assert not core.frames.robot_settled().settled and "pose is unknown" in core.frames.robot_settled().reason
    core.picking.pick_model_point(core.task.component, "pin_tip", (0.0, 0.0, 0.0))
    with pytest.raises(NotSettledError, match="link dropped"):
        core.picking.pick_image_point((10.0, 10.0))
    still_for(core, seconds=0.5)
    frame_now(core)
    core.picking.pick_image_point((10.0, 10.0))
    assert core.session.pairs.pairs()[0].view is not None


def test_pairs_without_a_robot_pose_are_not_solved(cell_and_site):
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    for k, name in enumerate(FEATURES[:4]):
        core.session.undo.push(
            AddPoint3D(core.session.pairs, core.task.component, name, (float(k), 0.0, 0.0), target=core.session.target)
        )
        core.session.undo.push(
            SetPixel(core.session.pairs, None, (10.0 * k, 5.0))
        )  # a script's picks, outside the core's frames
    with pytest.raises(CalibrationError, match="pairs 1, 2, 3, 4 carry no robot pose"):
        core.picking.calibrate()


def test_a_pick_on_a_frame_newer_than_the_joint_stream_holds_the_frame_before_it(cell_and_site):
    """The joint stream lags the camera by up to a sample period: a click that lands when the newest
    frame is 10 ms newer than the newest sample is made on the frame before it, not refused. A frame
    of a moving robot is refused all the same."""
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    q = task_joints(core)
    t_last = still_for(core, joints_deg=q)
    before = frame_now(core, index=1, t_s=t_last - 0.005)
    frame_now(core, index=2, t_s=t_last + 0.010)  # its joint samples are still on the way
    fixture = core.workcell.component(core.task.component)
    p = apply(fixture.item2world, fixture.features["pin_tip"])
    core.picking.pick_model_point(fixture.name, "pin_tip", p)
    core.picking.pick_image_point((320.0, 240.0))
    assert core.observations.still.frame is before
    assert np.allclose(core.session.pairs.get(core.picking.current_pair).view.joints_deg, q, atol=1e-6)
    core.close()
    # moving: the newest frame is judged (the robot moved before it), and refused with the reason
    core = OperatorCore(cell, site)
    t0 = still_for(core, joints_deg=q)
    for k in range(1, 20):
        sample(core, q + 0.5 * k, t0 + 0.02 * k)
    frame_now(core, index=1, t_s=t0 + 0.30)
    frame_now(core, index=2, t_s=t0 + 0.38)
    core.picking.pick_model_point(fixture.name, "pin_tip", p)
    with pytest.raises(NotSettledError, match="frame 2"):
        core.picking.pick_image_point((320.0, 240.0))
    core.close()
