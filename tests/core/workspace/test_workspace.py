"""The workspace file: round trip, atomic save, every kind of bad file; the correction exports."""

from calib_core.calibration.look_solving import calibrate
from calib_core.calibration.correction_from_look import StoreLook
from calib_core.calibration.commands import SetPixel
from calib_core.calibration.commands import AddPoint3D
import csv
import io
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from calib_core.calibration.session import CalibrationSession
from calib_core.camera.projection import project
from calib_core.errors import FileFormatError
from calib_core.frames import apply, invert
from calib_core.robot import solve_ik
from videocal_sim.test_bed import TestBed
from calib_core.workspace.exports import CSV_COLUMNS, corrections_csv, corrections_pdl2
from calib_core.workspace.workspace import Workspace, load_workspace, save_workspace


@pytest.fixture(scope="module")
def workspace():
    bed = TestBed.create()
    cell = bed.workcell
    task = cell.task("oru_1_grasp")
    q = solve_ik(bed.model_robot, task.approach2base, cell.home_joints_deg).q_deg
    s = CalibrationSession()
    s.set_target("oru_1_fixture")
    fx = cell.component("oru_1_fixture")
    for name in ("plate_top_left", "plate_top_right", "plate_bottom_right", "plate_bottom_left", "pin_tip"):
        p = apply(fx.item2world, fx.features[name])
        s.undo.push(AddPoint3D(s.pairs, "oru_1_fixture", name, p, target=s.target))
        s.undo.push(SetPixel(s.pairs, None, project(apply(invert(bed.true_cam2world(q)), p[None]), bed.intrinsics)[0]))
    s.undo.push(
        AddPoint3D(
            s.pairs,
            "oru_1_fixture",
            "boss_top_left",
            apply(fx.item2world, fx.features["boss_top_left"]),
            target=s.target,
        )
    )  # half a pair
    for _ in range(2):
        calibrate(s, bed.intrinsics, fx.item2world, bed.model_cam2world(q), bed.model_robot.fk(q), q)
        s.undo.push(StoreLook(s, task.name))
    return Workspace(
        str(cell.path), bed.intrinsics, dict(cell.task_locations), s.target, s.pairs.pairs(), s.corrections
    )


def test_round_trip(tmp_path, workspace):
    path = tmp_path / "w.json"
    save_workspace(path, workspace)
    back = load_workspace(path)
    assert back.intrinsics == workspace.intrinsics and back.target == "oru_1_fixture"
    assert back.pairs == workspace.pairs and back.pairs[-1].pixel is None
    assert list(back.task_locations) == list(workspace.task_locations)
    assert np.allclose(
        back.task_locations["oru_1_grasp"].tcp2base, workspace.task_locations["oru_1_grasp"].tcp2base, atol=1e-9
    )
    assert len(back.corrections.history("oru_1_grasp")) == 2
    a, b = back.corrections.latest("oru_1_grasp"), workspace.corrections.latest("oru_1_grasp")
    assert np.allclose(a.displacement_mm, b.displacement_mm) and np.allclose(
        a.tcp2base_measured, b.tcp2base_measured, atol=1e-9
    )


def test_a_failed_save_leaves_the_old_file_whole(tmp_path, workspace, monkeypatch):
    path = tmp_path / "w.json"
    save_workspace(path, workspace)
    before = path.read_bytes()

    def crash(*args, **kwargs):
        raise OSError("disk pulled out")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError):
        save_workspace(path, workspace)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["w.json"]  # no half-written file left behind


@pytest.mark.parametrize(
    "mutate, field, message",
    [
        (lambda t: t[: len(t) // 2], None, "not valid JSON"),
        (lambda t: json.dumps({"hello": 1}), "kind", "not a videocal workspace"),
        (
            lambda t: t.replace('"schema_version": 2', '"schema_version": 9'),
            "schema_version",
            "versions 1, 2, the file is version 9",
        ),
        (
            lambda t: _edit(t, lambda d: d["corrections"][0].update(joints_deg=[])),
            "corrections[0].joints_deg",
            "1 to 16 joint values",
        ),
        (lambda t: _edit(t, lambda d: d.update(cell="my cell")), "cell", "name, content_hash"),
        (
            lambda t: _edit(t, lambda d: d["corrections"][0].update(verdict=1e16)),
            "corrections[0].verdict",
            "must be one of ok, ambiguous, implausible, uncertain, failed, got 1e+16",
        ),
        (
            lambda t: _edit(t, lambda d: d["corrections"][0].update(confirmation=float("nan"))),
            "corrections[0].confirmation",
            "must be text, got float",
        ),
        (
            lambda t: _edit(t, lambda d: d["corrections"][0].update(source="pairs 1\nmovej([0,0,0,0,0,0])")),
            "corrections[0].source",
            "holds the control character U+000A",
        ),
        (
            lambda t: _edit(t, lambda d: d["corrections"][0].update(joints_deg=[0.0] * 500)),
            "corrections[0].joints_deg",
            "1 to 16 joint values",
        ),
        (
            lambda t: _edit(t, lambda d: d["pairs"][0].update(point_world_mm=[1, 2])),
            "pairs[0].point_world_mm",
            "3 finite numbers",
        ),
        (lambda t: _edit(t, lambda d: d["corrections"][1].pop("rms_px")), "corrections[1].rms_px", "missing"),
        (
            lambda t: _edit(t, lambda d: d["task_locations"][0]["tcp2base"].update(rpy=[0, "x", 0])),
            "task_locations[0].tcp2base.rpy",
            "3 finite numbers",
        ),
    ],
)
def test_bad_files_name_the_field(tmp_path, workspace, mutate, field, message):
    path = tmp_path / "w.json"
    save_workspace(path, workspace)
    path.write_text(mutate(path.read_text()))
    with pytest.raises(FileFormatError) as info:
        load_workspace(path)
    assert info.value.field == field and message in str(info.value) and str(path) in str(info.value)


def _edit(text, change):
    data = json.loads(text)
    change(data)
    return json.dumps(data)


def test_exports(tmp_path, workspace):
    rows = list(csv.reader(io.StringIO(corrections_csv(workspace.corrections))))
    assert tuple(rows[0]) == CSV_COLUMNS and len(rows) == 3
    c = workspace.corrections.latest("oru_1_grasp")
    assert float(rows[2][2]) == pytest.approx(c.displacement_mm[0], abs=1e-4)
    listing = corrections_pdl2(workspace.corrections, workspace.task_locations)
    target = workspace.corrections.corrected_target("oru_1_grasp", workspace.task_locations["oru_1_grasp"].tcp2base)
    assert f"POS({target[0, 3]:.3f}, {target[1, 3]:.3f}, {target[2, 3]:.3f}," in listing
    assert listing.splitlines()[2] == "VAR" and "END" in listing
    path = tmp_path / "w.json"
    save_workspace(path, workspace)
    run = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "export", str(path), "--format", "pdl2"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 0 and "oru_1_grasp_c := POS(" in run.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "app.cli.main", "export", str(tmp_path / "nope.json")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2 and "no such workspace file" in bad.stderr
    # a KRL data list named after its file; a file name KRL cannot take is one error line, and nothing is written
    krl = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "export",
            str(path),
            "--format",
            "krl",
            "--out",
            str(tmp_path / "cell_targets.dat"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert krl.returncode == 0 and (tmp_path / "cell_targets.dat").read_text().startswith("DEFDAT cell_targets PUBLIC")
    dashed = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "export",
            str(path),
            "--format",
            "krl",
            "--out",
            str(tmp_path / "cell-targets.dat"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (
        dashed.returncode == 2
        and dashed.stderr.startswith("error:")
        and "rename the output file" in dashed.stderr
        and "Traceback" not in dashed.stderr
    )
    assert not (tmp_path / "cell-targets.dat").exists()


def test_a_note_typed_over_lines_is_stored_as_one_line_and_read_back(tmp_path, workspace):
    """A conversion's note the operator typed with a line break is kept as one line: an export's remark cannot start
    a statement, and the file it is saved in reads back."""
    from dataclasses import replace

    task = workspace.corrections.tasks()[0]
    c = workspace.corrections.latest(task)
    typed = replace(c, source="converted: from a recording;\nmovej([0, 0, 0, 0, 0, 0])", confirmation="ok\r\nby me")
    assert typed.source == "converted: from a recording; movej([0, 0, 0, 0, 0, 0])"
    assert typed.confirmation == "ok  by me"
    workspace.corrections.add(typed)
    save_workspace(tmp_path / "w.json", workspace)
    back = load_workspace(tmp_path / "w.json").corrections.latest(task)
    assert (back.source, back.confirmation) == (typed.source, typed.confirmation)
