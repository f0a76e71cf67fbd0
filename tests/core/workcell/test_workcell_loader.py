"""The bundled workcell loads; every kind of bad file gives an error naming the file and field."""

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from calib_core.errors import FileFormatError
from calib_core.robot import solve_ik
from calib_core.workcell import DEFAULT_WORKCELL, load_workcell


def test_bundled_workcell():
    cell = load_workcell()
    names = [c.name for c in cell.components]
    assert {"rack_1", "rack_2", "oru_1", "drawer", "gripper_station", "screwdriver_station"} <= set(names)
    assert cell.triangle_count < 50_000
    grasp = cell.task("oru_1_grasp")
    assert np.allclose(grasp.tcp2base[:3, 3], [1146.24, -428.85, 1367.70])
    # The task location grasps the fixture pin: 25 mm in front of the plate, on its axis.
    pin_axis_point = cell.feature_in_base("oru_1_fixture", "pin_tip")
    assert np.linalg.norm(pin_axis_point - grasp.tcp2base[:3, 3]) == pytest.approx(20.0, abs=0.1)
    # Both the grasp and its approach are reachable.
    robot = cell.load_robot()
    q = solve_ik(robot, grasp.tcp2base, cell.home_joints_deg).q_deg
    solve_ik(robot, grasp.approach2base, q)
    assert np.allclose(grasp.approach2base[:3, 3], grasp.tcp2base[:3, 3] - 200 * grasp.tcp2base[:3, 2])


@pytest.fixture
def cell_copy(tmp_path):
    """A copy of the bundled workcell (file, meshes, robot, camera) to break."""
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(root / sub, tmp_path / sub)
    path = tmp_path / "workcell" / "workcell.yaml"
    return path, yaml.safe_load(path.read_text())


def _write(path: Path, data) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.mark.parametrize(
    "mutate, field, message",
    [
        (lambda d: d["components"][1].update(colour=[1, 0, 0]), "components[1]", "unknown key(s) colour"),
        (lambda d: d["components"][1].update(mesh="meshes/nothing.stl"), "components[1].mesh", "file not found"),
        (
            lambda d: d["components"][1].update(mesh_units="inch"),
            "components[1].mesh_units",
            "must be one of cm, m, mm",
        ),
        (lambda d: d["components"][2].update(name="rack_1"), "components[2].name", "duplicate component name"),
        (
            lambda d: d["components"][1]["placement"].update(rpy=[0, "ten", 0]),
            "components[1].placement.rpy[1]",
            "finite number",
        ),
        (
            lambda d: d["components"][1]["placement"].update(xyz=[0, 0]),
            "components[1].placement.xyz",
            "list of 3 numbers",
        ),
        (lambda d: d.update(units={"length": "m", "angle": "deg"}), "units", "mm and deg"),
        (lambda d: d.update(schema_version=7), "schema_version", "versions 1, 2"),
        (
            lambda d: d["task_locations"][0].update(component="oru_9"),
            "task_locations[0].component",
            "no component called 'oru_9'",
        ),
        (
            lambda d: d["components"][2]["features"].update(pin_tip=[1, 2]),
            "components[2].features.pin_tip",
            "list of 3 numbers",
        ),
        (
            lambda d: d["components"][2].update(form_tolerance_mm=-0.5),
            "components[2].form_tolerance_mm",
            "must lie in [0, 20] mm",
        ),
        (
            lambda d: d["components"][2].update(form_tolerance_mm="1 mm"),
            "components[2].form_tolerance_mm",
            "finite number",
        ),
        (lambda d: d["robot"]["frames"].update(flange="tool0"), "robot.frames.flange", "the URDF has no frame 'tool0'"),
        (
            lambda d: d["robot"]["frames"].update(tcp={"parent": "wrist", "xyz": [0, 0, 1], "rpy": [0, 0, 0]}),
            "robot.frames.tcp.parent",
            "no frame 'wrist'",
        ),
        (lambda d: d["robot"]["frames"].update(tool="flange"), "robot.frames", "unknown key(s) tool"),
        (lambda d: d["robot"]["frames"].update(base="link_2"), "robot.frames.base", "moves with joint"),
        (
            lambda d: d["robot"].update(home_joints_deg=[0, 0, 0, 0, 0, 0, 0]),
            "robot.home_joints_deg",
            "drives 6 joints (joint_1",
        ),
        (
            lambda d: d["robot"].update(home_joints_deg=[0, 0, 300, 0, 0, 0]),
            "robot.home_joints_deg[2]",
            "outside joint 'joint_3' limits",
        ),
        (lambda d: d["robot"].update(held_joints={"finger": 3}), "robot.held_joints", "no joint 'finger'"),
        (lambda d: d["robot"].update(package_paths=["nowhere"]), "robot.package_paths[0]", "folder not found"),
        (
            lambda d: d["robot"].update(controller={"joints": ["joint_1", "joint_2"]}),
            "robot.controller.joints",
            "must name each driven joint once",
        ),
        (
            lambda d: d["robot"].update(controller={"joints": ["joint_1"], "zero_offsets": [1, 2]}),
            "robot.controller.zero_offsets",
            "one value per controller joint",
        ),
        (lambda d: d.update(hand_eye_board={"xyz": [1, 2]}), "hand_eye_board", "missing key(s) rpy"),
        # names become controller code and YAML keys: no control characters
        (
            lambda d: d["task_locations"][0].update(name="oru_1\n  x := 0; END; DELETE"),
            "task_locations[0].name",
            "control character U+000A",
        ),
        (lambda d: d["components"][1].update(name="rack\u202e1"), "components[1].name", "control character U+202E"),
        (
            lambda d: d["components"][2]["features"].update({"pin\ttip": [1, 2, 3]}),
            "components[2].features.'pin\\ttip'",
            "control character U+0009",
        ),
    ],
)
def test_bad_files_name_file_and_field(cell_copy, mutate, field, message):
    path, data = cell_copy
    mutate(data)
    with pytest.raises(FileFormatError) as info:
        load_workcell(_write(path, data))
    assert info.value.field == field
    assert message in str(info.value)
    assert str(path) in str(info.value)


def test_unreadable_files(tmp_path, cell_copy):
    path, _ = cell_copy
    path.write_text("components: [unclosed")
    with pytest.raises(FileFormatError, match="not valid YAML"):
        load_workcell(path)
    with pytest.raises(FileFormatError, match="no such workcell file"):
        load_workcell(tmp_path / "none.yaml")
    broken = path.parent / "meshes" / "rack.stl"
    broken.write_bytes(b"solid nonsense\nthis is not an stl\n")
    path.write_text((DEFAULT_WORKCELL).read_text())
    with pytest.raises(FileFormatError, match=r"components\[1\].mesh"):
        load_workcell(path)


def test_a_dae_component_from_a_vendor_package_loads_in_metres(cell_copy):
    from tests.vendor_robots import ROBOTS, require

    path, data = cell_copy
    dae = require(ROBOTS / "ur_description" / "meshes" / "ur5" / "visual" / "base.dae")
    data["components"][1].update(mesh=str(dae), mesh_units="m")
    cell = load_workcell(_write(path, data))
    mesh = cell.components[1].mesh
    assert len(mesh.faces) > 1000
    assert 100 < mesh.extents[0] < 160  # the UR5's base, about 120 mm across, in mm


def test_feature_kinds_are_read_written_back_and_checked(tmp_path):
    import shutil

    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell
    from calib_core.workcell.writer import save_workcell

    cell = load_workcell(DEFAULT_WORKCELL)
    fixture = next(c for c in cell.components if c.name == "oru_1_fixture")
    boss = fixture.feature_kinds["boss_top_left"]
    assert boss.kind == "circle" and boss.radius_mm == 10.0 and boss.normal == (1.0, 0.0, 0.0)
    assert "plate_top_left" not in fixture.feature_kinds  # the plain form is a corner
    root = DEFAULT_WORKCELL.parents[1]
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(root / sub, tmp_path / sub)
    path = tmp_path / "workcell" / "workcell.yaml"
    again = load_workcell(path)
    again_fixture = next(c for c in again.components if c.name == "oru_1_fixture")
    from calib_core.workcell.feature_kinds import FeatureKind

    again_fixture.feature_kinds["plate_top_left"] = FeatureKind("point")
    save_workcell(again, path)
    text = path.read_text()
    assert "plate_top_left: {at: [0.0, -80.0, 60.0], kind: point}" in text and "# the knob's end face" in text
    reread = next(c for c in load_workcell(path).components if c.name == "oru_1_fixture")
    assert reread.feature_kinds["plate_top_left"].kind == "point" and reread.feature_kinds["boss_top_left"] == boss


@pytest.mark.parametrize(
    "entry, message",
    [
        ("{at: [0, 0, 0], kind: circle}", "a circle needs radius_mm"),
        ("{at: [0, 0, 0], kind: circle, radius_mm: -1, normal: [1, 0, 0]}", "radius_mm in"),
        ("{at: [0, 0, 0], kind: circle, radius_mm: 5, normal: [0, 0, 0]}", "not all zero"),
        ("{at: [0, 0, 0], kind: edge}", "kind"),
        ("{at: [0, 0, 0], kind: corner, radius_mm: 3}", "applies to a circle only"),
        ("{kind: point}", "missing key(s) at"),
    ],
)
def test_a_bad_feature_kind_names_its_field(tmp_path, entry, message):
    from calib_core.errors import FileFormatError
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell

    text = DEFAULT_WORKCELL.read_text().replace(
        "pin_tip: {at: [45, 0, 0], kind: circle, radius_mm: 20, normal: [1, 0, 0]}", f"pin_tip: {entry}", 1
    )
    path = DEFAULT_WORKCELL.parent / f".test-{tmp_path.name}.yaml"
    path.write_text(text)
    try:
        with pytest.raises(FileFormatError, match="pin_tip") as info:
            load_workcell(path)
        assert message in str(info.value)
    finally:
        path.unlink()


def test_a_parts_form_tolerance_is_read_and_new_components_write_it(cell_copy, tmp_path):
    """``form_tolerance_mm``: how far the part's features may lie from their CAD (1-sigma, mm); 0 when not stated."""
    from calib_core.workcell.writer import _component_entry

    path, data = cell_copy
    data["components"][2]["form_tolerance_mm"] = 0.4
    cell = load_workcell(_write(path, data))
    assert cell.components[2].form_tolerance_mm == 0.4 and cell.components[1].form_tolerance_mm == 0.0
    entry = _component_entry(cell.components[2], (path.parent / "meshes" / "rack.stl", "mm"), path.parent)
    assert entry["form_tolerance_mm"] == 0.4 and "form_tolerance_mm" not in _component_entry(
        cell.components[1], (path.parent / "meshes" / "rack.stl", "mm"), path.parent
    )
