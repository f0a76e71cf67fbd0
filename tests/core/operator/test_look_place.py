"""A correction is bound to where its look was made: a look from the approach pose or from a
recording is a measurement at its own pose, never the task's correction unless converted explicitly."""

from calib_core.calibration.commands import ClearPairs
import numpy as np
import pytest

from calib_core.calibration.look_place import LookNotAtTask, place_of_look
from calib_core.frames import make_transform, pose_difference, transform_from_rotvec_deg
from calib_core.link.joint_history import JointHistory
from calib_core.operator.core import OperatorCore
from calib_core.robot import solve_ik
from calib_core.connectors.frame import Frame
from calib_core.workcell.model import TaskLocation
from videocal_sim.sim_site import simulated_cell
from tests.core.operator.still_robot import frame_now, still_for
from tests.core.operator.perfect_operator import pick_all as _pick_all


@pytest.fixture(scope="module")
def cell_and_site():
    return simulated_cell(image_scale=0.5)


def _look(cell, site, joints_of):
    """A core whose pairs were picked perfectly on a still frame at ``joints_of(core)``, solved."""
    core = OperatorCore(cell, site)
    q = joints_of(core)
    still_for(core, joints_deg=q)
    frame_now(core)
    _pick_all(core, site.bed, q)
    core.picking.calibrate()
    return core, q


def _at_approach(core):
    return solve_ik(core.robot, core.task.approach2base, core.cell.home_joints).q_deg


def _at_task(core):
    return solve_ik(core.robot, core.task.tcp2base, core.cell.home_joints).q_deg


def test_a_look_from_the_approach_is_refused_as_the_tasks_correction(cell_and_site):
    core, _ = _look(*cell_and_site, _at_approach)
    place = core.desk.look_place()
    assert place.at == "elsewhere" and place.offset_mm == pytest.approx(core.task.approach_mm, abs=0.5)
    with pytest.raises(LookNotAtTask, match=r"200\.0 mm .* from .*'s pose") as refused:
        core.desk.store_correction()
    assert refused.value.change_mm > 0.1  # the window shows how far the commanded target would move
    assert core.session.corrections.history(core.task.name) == []


def test_kept_as_a_measurement_it_moves_nothing(cell_and_site):
    core, q = _look(*cell_and_site, _at_approach)
    kept = core.desk.store_measurement()
    table = core.session.corrections
    assert kept.kind == "measurement" and table.history(core.task.name) == [kept]
    assert table.latest(core.task.name) is None
    np.testing.assert_array_equal(table.corrected_target(core.task.name, core.task.tcp2base), core.task.tcp2base)
    core.undo()
    assert table.history(core.task.name) == []


def test_converted_explicitly_it_becomes_the_correction_with_what_the_operator_said(cell_and_site):
    core, _ = _look(*cell_and_site, _at_approach)
    with pytest.raises(LookNotAtTask) as refused:
        core.desk.store_correction()
    events = []
    core.log.event.connect(lambda kind, detail: events.append((kind, detail)))
    c = core.desk.store_correction(convert="converted by a test")
    assert c.kind == "correction" and core.session.corrections.latest(core.task.name) is c
    assert "converted: the look was made 200" in c.source and "converted by a test" in c.source
    assert [k for k, _ in events] == ["look_converted"]
    # what the window said would change is what changed
    d, r = pose_difference(
        core.session.corrections.corrected_target(core.task.name, core.task.tcp2base), core.task.tcp2base
    )
    assert np.linalg.norm(d) == pytest.approx(refused.value.change_mm, abs=1e-6) and np.linalg.norm(r) == pytest.approx(
        refused.value.change_deg, abs=1e-6
    )


def test_looks_at_the_task_and_at_its_corrected_pose_count(cell_and_site):
    cell, site = cell_and_site
    core, _ = _look(cell, site, _at_task)
    assert core.desk.look_place().at == "task"
    first = core.desk.store_correction()
    corrected = core.session.corrections.corrected_target(core.task.name, core.task.tcp2base)
    q_corrected = solve_ik(core.robot, corrected, core.cell.home_joints).q_deg
    core.session.undo.push(ClearPairs(core.session.pairs))
    still_for(core, joints_deg=q_corrected)
    frame_now(core, index=1)
    _pick_all(core, site.bed, q_corrected)
    core.picking.calibrate()
    assert core.desk.look_place().at == "corrected"
    second = core.desk.store_correction()
    assert core.session.corrections.history(core.task.name) == [first, second]


@pytest.mark.parametrize("name", ["sample_session.mcap", "live"])
def test_a_look_on_a_recording_is_not_the_live_tasks_correction(cell_and_site, name):
    """Whatever the recording is called: one named ``live`` (a file the user named so) is still a recording, since
    where a frame came from is a type, not its name (it once stored a 9 mm correction for the live task)."""
    cell, site = cell_and_site
    core = OperatorCore(cell, site)
    q = _at_task(core)
    times = np.arange(0.0, 1.0, 0.02)  # a still robot on the recording's time axis, then a frame of it
    core.frames.begin_replay(
        JointHistory.from_arrays(times, np.tile(q, (len(times), 1)), core.workcell.safety.settle_rule),
        name,
    )
    core.frames.observe_frame(Frame(np.zeros((480, 640, 3), np.uint8), 3, float(times[-1])), replayed=True)
    _pick_all(core, site.bed, q)
    core.picking.calibrate()
    core.frames.end_replay()  # "Close replay": the branched session stays open
    place = core.desk.look_place()
    assert place.at == "recording" and place.source == name
    with pytest.raises(LookNotAtTask, match=f"on the recording {name}"):
        core.desk.store_correction()
    assert core.session.corrections.latest(core.task.name) is None


def _task(tolerance_mm=1.0):
    return TaskLocation("t", make_transform(np.eye(3), [500.0, 0.0, 300.0]), 200.0, None, tolerance_mm)


@pytest.mark.parametrize(
    "shift_mm, turn_deg, at",
    [(0.0, 0.0, "task"), (0.9, 0.0, "task"), (1.1, 0.0, "elsewhere"), (0.0, 0.5, "task"), (0.0, 0.6, "elsewhere")],
)
def test_place_of_a_look_against_the_tasks_tolerance(shift_mm, turn_deg, at):
    task = _task()
    look = task.tcp2base @ transform_from_rotvec_deg([0.0, 0.0, turn_deg], [shift_mm, 0.0, 0.0])
    place = place_of_look(task, look, None, ())
    # the rotational tolerance is 1 mm seen at 100 mm: 0.573 deg
    assert place.at == at and place.offset_mm == pytest.approx(shift_mm) and place.offset_deg == pytest.approx(turn_deg)


def test_the_nearest_of_task_and_corrected_pose_is_reported():
    task = _task()
    corrected = task.tcp2base @ transform_from_rotvec_deg([0, 0, 0], [8.0, 0.0, 0.0])
    look = task.tcp2base @ transform_from_rotvec_deg([0, 0, 0], [8.3, 0.0, 0.0])
    place = place_of_look(task, look, corrected, ())
    assert place.at == "corrected" and place.offset_mm == pytest.approx(0.3)
    assert place_of_look(task, look, None, ()).at == "elsewhere"


def test_the_stored_correction_exports_as_a_krl_data_list_named_after_its_file_with_the_cells_tool(
    cell_and_site, tmp_path
):
    """*File > Export corrections* of the core: the listing is named after its file and carries the cell's tool."""
    import re

    from calib_core.frames import concat, invert

    cell, site = cell_and_site
    core, _ = _look(cell, site, _at_task)
    core.desk.store_correction()
    path = tmp_path / "cell_targets.dat"
    core.files.export_corrections(path, "krl")
    text = path.read_text()
    assert text.startswith("DEFDAT cell_targets PUBLIC")
    tool = concat(core.robot.fk(core.joints_deg, "tcp"), invert(core.robot.fk(core.joints_deg, "flange")))
    xyz = [float(v) for v in re.search(r"videocal_tool=\{X ([-\d.]+),Y ([-\d.]+),Z ([-\d.]+)", text).groups()]
    assert np.allclose(xyz, tool[:3, 3], atol=1e-3)
