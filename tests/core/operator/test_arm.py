"""The arm model on its own (no window): a move is previewed, sent over the simulated controller's link
and followed to the controller's answer, in events; a move that needs a confirmation sends nothing; a
Stop voids the confirmations waiting; a replay refuses every move.

The link's reader thread hands its calls to ``call_soon``; here, as in the window, they queue to the
test's thread, which runs them until the arm's state says what the test waits for."""

import queue

import numpy as np
import pytest

from calib_core.calibration.errors import CalibrationError
from calib_core.link.joint_history import JointHistory
from calib_core.operator.core import OperatorCore
from calib_core.operator.motion import Motion
from calib_core.operator.move_preview import MoveNeedsConfirmation
from videocal_sim.sim_site import simulated_cell


@pytest.fixture
def arm_and_pump():
    calls: queue.Queue = queue.Queue()
    cell, site = simulated_cell(image_scale=0.25)
    core = OperatorCore(cell, site, call_soon=lambda fn, *args: calls.put((fn, args)))

    def pump_until(predicate, timeout_s: float = 30.0):
        """Run the link's queued calls on this thread until ``predicate()`` holds."""
        while not predicate():
            fn, args = calls.get(timeout=timeout_s)  # queue.Empty: the link said nothing for timeout_s
            fn(*args)

    core.start_controller()
    pump_until(lambda: core.arm.last_sample_s is not None)
    yield core.arm, pump_until
    core.close()


def _record(arm):
    seen = []
    arm.move_previewed.connect(lambda p: seen.append(("previewed", p.what)))
    arm.motion_changed.connect(lambda s: seen.append(("motion", s.motion.value)))
    arm.move_finished.connect(lambda what, error: seen.append(("finished", what, error)))
    arm.prompts_withdrawn.connect(lambda: seen.append(("withdrawn",)))
    return seen


def test_a_move_is_previewed_sent_and_followed_to_the_controllers_answer(arm_and_pump):
    arm, pump_until = arm_and_pump
    seen = _record(arm)
    q = np.array(arm.joints_deg, dtype=float)
    q[0] += 3.0  # small: no confirmation needed
    arm.move_joints(q, "a little left")
    assert seen == [("previewed", "a little left"), ("motion", "moving")]
    pump_until(lambda: arm.state.motion is Motion.ARRIVED and np.max(np.abs(arm.joints_deg - q)) < 1e-3)
    assert seen[-2:] == [("motion", "arrived"), ("finished", "a little left", "")]


def test_a_move_that_needs_a_confirmation_sends_nothing_and_a_stop_voids_its_confirmation(arm_and_pump):
    arm, pump_until = arm_and_pump
    seen = _record(arm)
    before = np.array(arm.joints_deg)
    q = before.copy()
    q[0] += arm.cell.workcell.safety.confirm_joint_change_deg + 10.0
    with pytest.raises(MoveNeedsConfirmation) as asked:
        arm.move_joints(q, "far")
    assert seen == [("previewed", "far")] and arm.state.motion is Motion.IDLE and arm.pending_move is None
    arm.stop()
    assert seen[-1] == ("withdrawn",)
    with pytest.raises(CalibrationError, match="stopped after this move was asked for"):
        arm.move_joints(q, "far", confirmed=asked.value.confirmation)
    assert arm.state.motion is Motion.IDLE and arm.pending_move is None
    with pytest.raises(MoveNeedsConfirmation) as again:  # asked again after the Stop, answered: it goes
        arm.move_joints(q, "far")
    arm.move_joints(q, "far", confirmed=again.value.confirmation)
    pump_until(lambda: arm.state.motion is Motion.ARRIVED)
    assert seen[-1] == ("finished", "far", "")


def test_no_move_while_a_recording_is_replayed(arm_and_pump):
    arm, _ = arm_and_pump
    seen = _record(arm)
    arm.observations.replay(JointHistory(joint_names=arm.robot.joint_names), "take.mcap")
    q = np.array(arm.joints_deg, dtype=float)
    q[0] += 3.0
    with pytest.raises(CalibrationError, match="recording is being replayed"):
        arm.move_joints(q, "a little left")
    assert seen == [] and arm.pending_move is None  # not even previewed: nothing reaches the link
    arm.observations.go_live()
    arm.move_joints(q, "a little left")
    assert arm.state.motion is Motion.MOVING
