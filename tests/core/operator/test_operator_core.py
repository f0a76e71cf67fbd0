"""The operator core without a window: the pair being made and Accept, undo, the cell's edits and their
events, and a workspace bound to its cell."""

import numpy as np
import pytest

from calib_core.undo import Command

from calib_core.errors import OperatorError
from calib_core.operator.cell import Cell, CellMismatchError
from calib_core.operator.core import OperatorCore
from calib_core.workspace.workspace import load_workspace
from tests.core.operator.still_robot import frame_now, still_for


@pytest.fixture
def core():
    return OperatorCore(Cell.open())


def test_point_then_accept_and_a_second_click_moves_the_image_point(core):
    events = []
    core.log.event.connect(lambda kind, detail: events.append((kind, detail)))
    fixture = core.workcell.component("oru_1_fixture")
    with pytest.raises(OperatorError, match="nothing to accept"):
        core.picking.accept_pair()
    n = core.picking.pick_model_point("oru_1_fixture", "pin_tip", fixture.item2world[:3, 3])
    with pytest.raises(OperatorError, match=f"pair {n} \\(pin_tip\\) has no point on the camera image"):
        core.picking.accept_pair()
    still_for(core)
    frame_now(core)
    core.picking.pick_image_point((100.0, 200.0))
    core.picking.pick_image_point((101.5, 199.0))  # not accepted yet: the click moves it
    assert core.session.pairs.get(n).pixel == (101.5, 199.0) and len(core.session.pairs) == 1
    assert core.picking.accept_pair() == n and core.picking.current_pair is None
    assert [e for e in events if e[0] != "frame_held"] == [("pair_accepted", {"number": n})]
    # After Accept a click on the image starts nothing: the model point comes first.
    with pytest.raises(OperatorError, match="pick the point on the model"):
        core.picking.pick_image_point((5.0, 5.0))
    # A new model pick replaces one still waiting for its image point.
    m = core.picking.pick_model_point("oru_1_fixture", "plate_top_left", fixture.item2world[:3, 3])
    core.picking.pick_model_point("oru_1_fixture", "plate_top_right", fixture.item2world[:3, 3])
    assert m not in [p.number for p in core.session.pairs] and len(core.session.pairs) == 2
    assert core.undo() is not None and core.picking.current_pair is None


def test_cell_edits_are_undoable_and_change_the_identity(core, tmp_path):
    changed = []
    core.cell.scene_changed.connect(lambda: changed.append("scene"))
    core.tasks.changed.connect(lambda name: changed.append(name))
    before = core.cell.identity
    mesh = core.workcell.path.parent / "meshes" / "drawer.stl"
    core.editor.add_component(mesh, "crate")
    core.editor.place_component("crate", [1200, 0, 500], [0, 0, 45])
    core.editor.place_component("crate", [1210, 0, 500], [0, 0, 45])
    core.editor.add_feature("crate", "corner", [10, 20, 30])
    core.editor.add_task_location("over_crate", np.eye(4) @ np.diag([1, 1, 1, 1.0]), 100.0, "crate")
    assert changed == ["scene", "scene", "scene", "scene", "over_crate"]
    assert core.cell.identity.content_hash != before.content_hash and core.editor.dirty
    labels = [core.undo() for _ in range(4)]
    assert labels == ["Add task location over_crate", "Add feature crate/corner", "Place crate", "Add component crate"]
    assert (
        "crate" not in [c.name for c in core.workcell.components] and "over_crate" not in core.workcell.task_locations
    )
    assert core.cell.identity == before  # back to the cell as loaded
    with pytest.raises(OperatorError, match="component name"):
        core.editor.add_component(mesh, "a: b")


def test_an_approach_edit_tells_the_task_choice_on_do_undo_and_redo(core):
    task = core.workcell.task("oru_1_grasp")
    told = []
    core.tasks.changed.connect(told.append)
    before = task.approach_mm
    core.editor.set_task_approach(task.name, before + 25.0)
    assert core.workcell.task(task.name).approach_mm == before + 25.0 and core.editor.dirty
    core.undo()
    assert core.workcell.task(task.name).approach_mm == before
    core.session.undo.redo()
    assert core.workcell.task(task.name).approach_mm == before + 25.0
    assert told == [task.name] * 3
    core.session.undo.push(_Nothing())  # an edit of something else: the cell is not told
    assert told == [task.name] * 3


class _Nothing(Command):
    label = "nothing"

    def do(self) -> None:
        pass

    def undo(self) -> None:
        pass


def test_a_workspace_opens_on_its_own_cell_only(core, tmp_path):
    path = tmp_path / "w.json"
    core.files.save_workspace(path)
    assert load_workspace(path).cell == core.cell.identity.to_dict()
    core.close()  # one window at a time on a workspace file
    other = OperatorCore(Cell.open())
    other.editor.add_feature("oru_1", "extra", [1, 2, 3])  # now another cell
    with pytest.raises(CellMismatchError, match="belongs to the cell 'space station robotic test bed'"):
        other.files.open_workspace(path)
    other.undo()
    other.files.open_workspace(path)  # the same cell again
