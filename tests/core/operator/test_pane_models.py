"""The panes' models: each pane's events are its parts' own, and the settings a model makes are the core's undoable
commands (a pane that sets through its model leaves what it set on the undo stack)."""

import numpy as np

from calib_core.operator.core import OperatorCore
from calib_core.operator.panes.camera import CameraPaneModel
from calib_core.operator.panes.cell_editing import CellPaneModel
from calib_core.operator.panes.commands import CommandsPaneModel
from calib_core.operator.panes.pairs import PairsTableModel
from videocal_sim.sim_site import simulated_cell


def _core() -> OperatorCore:
    cell, site = simulated_cell(image_scale=0.25)
    return OperatorCore(cell, site)


def test_a_pane_s_events_are_its_parts_own():
    core = _core()
    model = CameraPaneModel(core.cell, core.frames, core.picking, core.session, core.arm, core.finder)
    seen = []
    model.pairs_changed.connect(lambda *event: seen.append(event))
    target = core.session.target
    point = core.workcell.component(target).item2world[:3, 3]
    number = core.picking.pick_model_point(target, None, point)
    assert seen and seen[-1][1] == number  # the pair added, told through the pane's model
    assert model.pairs.pending().number == number and model.target == target
    assert np.array_equal(model.joints_deg, core.arm.joints_deg)


def test_the_command_panel_s_settings_are_undoable():
    core = _core()
    model = CommandsPaneModel(core.cell, core.session, core.tasks, core.editor)
    model.set_option("robust", True)
    assert core.session.options.robust
    model.set_option("robust", True)  # the value it has: nothing recorded
    assert core.undo() == "Use the robust option" and not core.session.options.robust
    task = model.task_names[0]
    model.choose_task(task)
    before = model.task.approach_mm
    model.set_task_approach(before + 25.0)
    assert core.workcell.task(task).approach_mm == before + 25.0
    core.undo()
    assert core.workcell.task(task).approach_mm == before
    assert core.session.target in model.target_names


def test_a_pair_left_out_from_the_table_is_one_undo_step_and_a_repeat_is_none():
    core = _core()
    table = PairsTableModel(core.session)
    target = core.session.target
    number = core.picking.pick_model_point(target, None, core.workcell.component(target).item2world[:3, 3])
    done = []
    core.session.undo.applied.connect(done.append)
    table.set_enabled(number, False)
    table.set_enabled(number, False)  # already left out: not done or recorded again
    assert not core.session.pairs.get(number).enabled and [c.label for c in done] == [f"Disable pair {number}"]
    assert core.undo() == f"Disable pair {number}" and core.session.pairs.get(number).enabled


def test_a_task_location_added_without_a_name_gets_the_next_one_and_is_said():
    core = _core()
    model = CellPaneModel(core.cell, core.editor, core.session, core.arm, core.log)
    said = []
    core.log.message.connect(said.append)
    count = len(core.workcell.task_locations)
    name = model.add_task_location("  ", model.tcp2base, 30.0)
    assert name == f"location_{count + 1}" and name in core.workcell.task_locations
    assert said[-1] == f"task location {name} added"
    assert np.allclose(core.workcell.task(name).tcp2base, model.tcp2base)
