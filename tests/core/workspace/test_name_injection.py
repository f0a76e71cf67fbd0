"""Names from the user never become controller code (a task name with a newline exported
``:= 0; END; DELETE`` as PDL2 statements between VAR and BEGIN, exit 0)."""

import json
import subprocess
import sys

import numpy as np
import pytest

from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.camera.intrinsics import Intrinsics
from calib_core.errors import FileFormatError
from calib_core.frames import make_transform
from calib_core.names import InvalidNameError, check_name, check_typed_name
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.controller_formats import FORMATS, controller_listing
from calib_core.workspace.workspace import Workspace, load_workspace, save_workspace

EVIL = "oru_1\n  x := 0; END; DELETE"
T = make_transform(np.eye(3), [500.0, 0.0, 300.0])


def _table(name: str) -> tuple[CorrectionTable, dict]:
    table = CorrectionTable()
    delta = make_transform(np.eye(3), [1.0, 0.0, 0.0])
    table.add(
        Correction(
            name,
            T,
            delta @ T,
            np.array([1.0, 0, 0]),
            np.zeros(3),
            np.full(3, 0.05),
            np.full(3, 0.01),
            np.zeros(6),
            0.3,
            6,
        )
    )
    return table, {name: TaskLocation(name, T, 100.0)}


@pytest.mark.parametrize(
    "name, ok",
    [
        ("oru_1_grasp", True),
        ("Pick 2 (left)", True),
        ("Greifer-Ä", True),
        (EVIL, False),
        ("a\rb", False),
        ("tab\there", False),
        ("bidi\u202eevil", False),
        ("", False),
        ("  ", False),
        (" lead", False),
        ("x" * 101, False),
        (3, False),
    ],
)
def test_check_name(name, ok):
    if ok:
        assert check_name(name, "task location") == name
    else:
        with pytest.raises(InvalidNameError, match="task location name"):
            check_name(name, "task location")


def test_names_typed_in_the_window_keep_out_of_yaml_too():
    with pytest.raises(InvalidNameError, match="use letters"):
        check_typed_name("a: b", "feature")


@pytest.mark.parametrize("fmt", FORMATS)
def test_an_export_never_writes_an_unchecked_name(fmt):
    table, tasks = _table(EVIL)
    with pytest.raises(InvalidNameError, match="control character U\\+000A"):
        controller_listing(fmt, table, tasks)


@pytest.mark.parametrize("fmt", FORMATS)
def test_remarks_keep_to_characters_no_language_reads_as_code(fmt):
    table, tasks = _table('pick;"left" (2)')
    text = controller_listing(fmt, table, tasks)
    assert "pick__left_ _2_: displacement" in text and ';"left"' not in text


def _workspace_with_task(tmp_path, name):
    table, tasks = _table("oru_1_grasp")
    ws = Workspace("cell.yaml", Intrinsics(800, 800, 320, 240, 640, 480, (0.0,) * 5), tasks, None, [], table)
    path = tmp_path / "w.json"
    save_workspace(path, ws)
    data = json.loads(path.read_text())
    data["task_locations"][0]["name"] = name
    data["corrections"][0]["task"] = name
    path.write_text(json.dumps(data))
    return path


def test_a_workspace_with_such_a_name_is_refused_naming_the_field(tmp_path):
    path = _workspace_with_task(tmp_path, EVIL)
    with pytest.raises(FileFormatError, match=r"task_locations\[0\]\.name.*control character"):
        load_workspace(path)


def test_videocal_export_refuses_it_and_writes_nothing(tmp_path):
    path = _workspace_with_task(tmp_path, EVIL)
    out = tmp_path / "corr.pdl"
    done = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "export", str(path), "--format", "pdl2", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and "task_locations[0].name" in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()
