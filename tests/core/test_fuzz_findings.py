"""What the fuzz suite found, kept as plain regression tests: values of a type no check expected
(a list where a name goes, an integer past any float, a boolean where a list goes)."""

import json
import shutil

import pytest
import yaml

from calib_core.errors import FileFormatError
from calib_core.workcell import DEFAULT_WORKCELL, load_workcell
from calib_core.workspace.workspace import load_workspace
from tests.fuzz.run_loader import _workspace_doc


@pytest.fixture
def folder(tmp_path):
    for sub in ("workcell", "robot", "camera"):
        shutil.copytree(DEFAULT_WORKCELL.parents[1] / sub, tmp_path / sub)
    return tmp_path


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d["components"][1].update(mesh_units=["mm"]), "components[1].mesh_units"),
        (lambda d: d["components"][1].update(kind=[1]), "components[1].kind"),
        (lambda d: d["components"][1]["placement"].update(xyz=[2**1100, 0, 0]), "components[1].placement.xyz[0]"),
        (lambda d: d.update(schema_version=[2]), "schema_version"),
    ],
)
def test_workcell_values_of_an_unexpected_type(folder, edit, field):
    path = folder / "workcell" / "workcell.yaml"
    data = yaml.safe_load(path.read_text())
    edit(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(FileFormatError) as info:
        load_workcell(path)
    assert info.value.field == field


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda d: d.update(verifications=True), "verifications"),
        (lambda d: d["task_locations"][0].update(approach_mm=2**70), "task_locations[0].approach_mm"),
        (lambda d: d["corrections"][0].update(time_s=10**400), "corrections[0].time_s"),
    ],
)
def test_workspace_values_of_an_unexpected_type(folder, edit, field):
    data = _workspace_doc(folder)
    edit(data)
    path = folder / "w.json"
    path.write_text(json.dumps(data))
    with pytest.raises(FileFormatError) as info:
        load_workspace(path)
    assert info.value.field == field


@pytest.mark.parametrize("name", ["meshes/a\x00b.stl", "x" * 5000 + ".stl"])
def test_a_mesh_path_no_file_system_takes(folder, name):
    path = folder / "workcell" / "workcell.yaml"
    data = yaml.safe_load(path.read_text())
    data["components"][1]["mesh"] = name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(FileFormatError, match="not a usable file name") as info:
        load_workcell(path)
    assert info.value.field == "components[1].mesh"


def test_a_detector_parameter_past_a_c_int_is_refused_naming_it(tmp_path):
    """The reliability bench's fuzzing: ``integer won't fit into a C int`` escaped as a ValueError."""
    from calib_core.vision.target_detection import load_detector_settings

    path = tmp_path / "detector.yaml"
    path.write_text(yaml.safe_dump({"aruco": {"adaptiveThreshWinSizeMax": 10**12}}))
    with pytest.raises(FileFormatError, match="OpenCV refuses 1000000000000") as info:
        load_detector_settings(path)
    assert info.value.field == "aruco.adaptiveThreshWinSizeMax"


def test_a_file_name_with_a_nul_byte_in_a_data_file_is_refused(tmp_path):
    """cal_data.yaml naming its pose file '\\x00': ``embedded null byte`` escaped as a ValueError."""
    from calib_core.documents import read_yaml

    with pytest.raises(FileFormatError, match="not a usable file name"):
        read_yaml(tmp_path / "a\0b.yaml", "pose file")


def test_a_huge_integer_for_a_detector_number_is_taken_as_a_float_or_refused_naming_it(tmp_path):
    """``ufunc 'isfinite' not supported`` for an integer past 2^63 escaped as a TypeError (reliability bench)."""
    from calib_core.vision.target_detection import load_detector_settings

    path = tmp_path / "detector.yaml"
    path.write_text("circle_blobs:\n  minArea: 1180591620717411303423\n")
    assert load_detector_settings(path).circle_blobs.minArea == pytest.approx(1.1805916e21)
    path.write_text(f"circle_blobs:\n  minArea: {10**400}\n")
    with pytest.raises(FileFormatError) as info:
        load_detector_settings(path)
    assert info.value.field == "circle_blobs.minArea"
