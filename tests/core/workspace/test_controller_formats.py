"""Corrected targets in each controller's conventions, checked against an independent conversion
(scipy, rebuilt from the printed numbers with the vendor's own definition) and against examples in
the vendors' documentation."""

import csv
import io
import json
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib_core.calibration.corrections import Correction, CorrectionTable
from calib_core.frames import make_transform, transform_from_xyz_rpy
from calib_core.workcell.model import TaskLocation
from calib_core.workspace.controller_formats import controller_listing, unique_identifiers
from calib_core.workspace.vendor_poses import fanuc_position, krl_frame, rapid_robtarget, urscript_pose
from calib_core.workspace.exports import CSV_COLUMNS, corrections_csv, corrections_json

RNG = np.random.default_rng(3)
POSES = [transform_from_xyz_rpy(RNG.uniform(-900, 900, 3), RNG.uniform(-170, 170, 3)) for _ in range(20)]
_NUM = r"(-?\d+\.?\d*(?:E\d+)?)"


def _numbers(text: str) -> np.ndarray:
    return np.array([float(v) for v in re.findall(_NUM, text)])


@pytest.mark.parametrize("T", POSES)
def test_urscript_rotation_vector_in_metres(T):
    x, y, z, rx, ry, rz = _numbers(urscript_pose(T))
    assert np.allclose([x, y, z], T[:3, 3] / 1000, atol=1e-6)
    assert np.allclose(Rotation.from_rotvec([rx, ry, rz]).as_matrix(), T[:3, :3], atol=1e-5)


@pytest.mark.parametrize("T", POSES)
def test_rapid_quaternion_scalar_first(T):
    values = _numbers(rapid_robtarget(T))
    xyz, (q1, q2, q3, q4) = values[:3], values[3:7]
    assert np.allclose(xyz, T[:3, 3], atol=1e-3)
    assert q1 >= 0 and abs(np.linalg.norm([q1, q2, q3, q4]) - 1) < 1e-7
    assert np.allclose(Rotation.from_quat([q2, q3, q4, q1]).as_matrix(), T[:3, :3], atol=1e-7)  # scipy: scalar last


@pytest.mark.parametrize("T", POSES)
def test_krl_abc_is_z_then_y_then_x(T):
    x, y, z, a, b, c = _numbers(krl_frame(T))
    R = (
        Rotation.from_euler("z", a, degrees=True)
        * Rotation.from_euler("y", b, degrees=True)
        * Rotation.from_euler("x", c, degrees=True)
    )
    assert np.allclose([x, y, z], T[:3, 3], atol=1e-3) and np.allclose(R.as_matrix(), T[:3, :3], atol=1e-5)


@pytest.mark.parametrize("T", POSES)
def test_fanuc_wpr_is_fixed_x_then_y_then_z(T):
    x, y, z, w, p, r = fanuc_position(T)
    R = (
        Rotation.from_euler("z", r, degrees=True)
        * Rotation.from_euler("y", p, degrees=True)
        * Rotation.from_euler("x", w, degrees=True)
    )
    assert np.allclose([x, y, z], T[:3, 3]) and np.allclose(R.as_matrix(), T[:3, :3], atol=1e-9)


def test_examples_from_the_vendors_documentation():
    # URScript manual: p[0.2, 0.5, 0.1, 1.57, 0, 0] is 200, 500, 100 mm turned 90 deg about x.
    assert (
        urscript_pose(transform_from_xyz_rpy([200, 500, 100], [90, 0, 0]))
        == "p[0.200000, 0.500000, 0.100000, 1.570796, 0.000000, 0.000000]"
    )
    # RAPID manual, robtarget: [[600, 500, 225.3], [1, 0, 0, 0], ...] is the base orientation.
    assert rapid_robtarget(make_transform(np.eye(3), [600, 500, 225.3])).startswith(
        "[[600.000,500.000,225.300],[1.00000000,0.00000000,0.00000000,0.00000000]"
    )
    # ...and a tool turned 180 deg about y (pointing down): [0, 0, 1, 0].
    assert "[0.00000000,0.00000000,1.00000000,0.00000000]" in rapid_robtarget(
        transform_from_xyz_rpy([0, 0, 0], [0, 180, 0])
    )
    # KRL: {X 100, Y 200, Z 300, A 90, B 0, C 0}: A turns about Z.
    assert (
        krl_frame(transform_from_xyz_rpy([100, 200, 300], [0, 0, 90]))
        == "{X 100.000,Y 200.000,Z 300.000,A 90.0000,B 0.0000,C 0.0000}"
    )
    # FANUC: W, P, R about the fixed x, y, z axes: the tool pointing down is W 180.
    assert np.allclose(fanuc_position(transform_from_xyz_rpy([0, 0, 0], [180, 0, 0]))[3:], [180, 0, 0])


def test_names_stay_unique_after_the_vendors_length_limit():
    names = ["rack_2_orbital_unit_grasp_A", "rack_2_orbital_unit_grasp_B", "1st pose", "Rack_2_orbital_unit_grasp_C"]
    idents = unique_identifiers(names, 24)
    assert len(set(v.lower() for v in idents.values())) == 4
    assert all(len(v) <= 24 and v[0].isalpha() and re.fullmatch(r"\w+", v) for v in idents.values())


@pytest.fixture
def table():
    tasks = {
        name: TaskLocation(name, transform_from_xyz_rpy([800 + 10 * k, -200, 900], [20, 90, 0]), 150.0, None)
        for k, name in enumerate(["rack_2_orbital_unit_grasp_A", "rack_2_orbital_unit_grasp_B"])
    }
    t = CorrectionTable()
    for k, (name, task) in enumerate(tasks.items()):
        measured = transform_from_xyz_rpy([1.5 + k, -2.0, 0.7], [0.1, -0.2, 0.05]) @ task.tcp2base
        t.add(
            Correction(
                name,
                task.tcp2base,
                measured,
                np.array([1.5 + k, -2.0, 0.7]),
                np.array([0.1, -0.2, 0.05]),
                np.full(3, 0.1),
                np.full(3, 0.01),
                np.zeros(6),
                0.4,
                9,
                source="=HYPERLINK(1)",
            )
        )
    return t, tasks


@pytest.mark.parametrize(
    "fmt, declaration",
    [
        ("urscript", "global "),
        ("rapid", "CONST robtarget "),
        ("krl", "DECL GLOBAL FRAME "),
        ("fanuc", '"]{'),
        ("pdl2", " := POS("),
    ],
)
def test_listings_declare_each_corrected_target_once(table, fmt, declaration):
    t, tasks = table
    text = controller_listing(fmt, t, tasks)
    assert text.count(declaration) == 2
    # The second target is the first shifted by 10 mm in x, and the listing holds the corrected one.
    target = t.corrected_target("rack_2_orbital_unit_grasp_B", tasks["rack_2_orbital_unit_grasp_B"].tcp2base)
    expected_x = target[0, 3] / (1000.0 if fmt == "urscript" else 1.0)
    assert f"{expected_x:.3f}" in text


def test_csv_and_json_hold_the_target_to_command(table):
    t, tasks = table
    rows = list(csv.reader(io.StringIO(corrections_csv(t, tasks))))
    assert tuple(rows[0]) == CSV_COLUMNS
    row = dict(zip(rows[0], rows[1]))
    target = t.corrected_target(row["task"], tasks[row["task"]].tcp2base)
    assert float(row["target_x_mm"]) == pytest.approx(target[0, 3], abs=1e-3)
    assert row["source"].startswith("'=")  # a spreadsheet must not run it
    data = json.loads(corrections_json(t, tasks))
    assert data["frame"] == "base" and np.allclose(data["corrections"][0]["target_to_command"]["xyz"], target[:3, 3])
    assert (
        row["tool_x_mm"] == "" and "tool_on_flange" not in data
    )  # without the robot: no tool, and said so by nothing made up


def test_csv_and_json_carry_the_tool_the_targets_are_for(table):
    """A target to command is for one TCP: the CSV's tool columns and the JSON's tool_on_flange give it (mm, deg),
    as the cell's robot has it on its flange."""
    from calib_core.frames import transform_from_xyz_rpy
    from calib_core.workcell import DEFAULT_WORKCELL, load_workcell
    from calib_core.workspace.exports import tool_on_flange

    t, tasks = table
    tool = tool_on_flange(load_workcell(DEFAULT_WORKCELL).load_robot())
    rows = list(csv.reader(io.StringIO(corrections_csv(t, tasks, tool))))
    row = dict(zip(rows[0], rows[1]))
    written = transform_from_xyz_rpy(
        [float(row[f"tool_{a}_mm"]) for a in "xyz"], [float(row[f"tool_{a}_deg"]) for a in ("roll", "pitch", "yaw")]
    )
    np.testing.assert_allclose(written, tool, atol=1e-3)
    data = json.loads(corrections_json(t, tasks, tool))
    np.testing.assert_allclose(
        transform_from_xyz_rpy(data["tool_on_flange"]["xyz"], data["tool_on_flange"]["rpy"]), tool, atol=1e-6
    )


def test_each_listing_is_named_after_its_file_as_the_controller_requires(table):
    """KRL loads a data list only when its DEFDAT is the file's name; FANUC loads an .ls under its /PROG name; a
    file name the language cannot take is refused before anything is written, naming the rule."""
    from calib_core.names import InvalidNameError

    t, tasks = table
    assert controller_listing("krl", t, tasks, "cell_targets").startswith("DEFDAT cell_targets PUBLIC\n")
    assert controller_listing("rapid", t, tasks, "CellTargets").startswith("MODULE CellTargets\n")
    fanuc = controller_listing("fanuc", t, tasks, "cell_targets")
    assert fanuc.startswith("/PROG  CELL_TARGETS\n/ATTR\n")
    # the /ATTR section as the controller writes it: its fields in order, the line count that of /MN
    attr = fanuc[fanuc.index("/ATTR") : fanuc.index("/MN")]
    fields = [line.split("=")[0].strip() for line in attr.splitlines()[1:] if "=" in line and not line.startswith(" ")]
    assert fields[:11] == [
        "OWNER",
        "COMMENT",
        "PROG_SIZE",
        "CREATE",
        "MODIFIED",
        "FILE_NAME",
        "VERSION",
        "LINE_COUNT",
        "MEMORY_SIZE",
        "PROTECT",
        "TCD:  STACK_SIZE",
    ]
    mn = fanuc[fanuc.index("/MN") + 4 : fanuc.index("/POS")].strip().splitlines()
    assert f"LINE_COUNT\t= {len(mn)};" in attr and re.search(
        r"CREATE\t\t= DATE \d\d-\d\d-\d\d  TIME \d\d:\d\d:\d\d;", attr
    )
    assert controller_listing("krl", t, tasks).startswith("DEFDAT videocal_corrections PUBLIC")  # no file: the default
    for fmt, bad in (("krl", "my-targets"), ("krl", "a" * 25), ("fanuc", "1cell")):
        with pytest.raises(InvalidNameError, match="rename the output file"):
            controller_listing(fmt, t, tasks, bad)


def test_each_listing_carries_the_tool_its_targets_are_for(table):
    """The TCP on the flange in each language's own form, read back from the printed numbers with the vendor's
    definition: URScript set_tcp (m, rotation vector), RAPID tooldata (robhold, pose, tool0's load), KRL FRAME
    (A about Z, B about Y, C about X), FANUC W P R, PDL2 $TOOL."""
    t, tasks = table
    tool = transform_from_xyz_rpy([12.5, -3.0, 187.25], [0.0, 30.0, 90.0])
    ur = controller_listing("urscript", t, tasks, tool=tool)
    x, y, z, rx, ry, rz = _numbers(re.search(r"set_tcp\(p\[([^\]]*)\]\)", ur).group(1))
    assert np.allclose([x, y, z], tool[:3, 3] / 1000, atol=1e-6) and np.allclose(
        Rotation.from_rotvec([rx, ry, rz]).as_matrix(), tool[:3, :3], atol=1e-5
    )
    rapid = controller_listing("rapid", t, tasks, tool=tool)
    data = re.search(
        r"PERS tooldata videocal_tool := "
        r"\[TRUE,\[\[([^\]]*)\],\[([^\]]*)\]\],\[0.001,\[0,0,0.001\],\[1,0,0,0\],0,0,0\]\];",
        rapid,
    )
    assert data, rapid
    q1, q2, q3, q4 = _numbers(data.group(2))
    assert np.allclose(_numbers(data.group(1)), tool[:3, 3], atol=1e-3) and np.allclose(
        Rotation.from_quat([q2, q3, q4, q1]).as_matrix(), tool[:3, :3], atol=1e-6
    )
    krl = controller_listing("krl", t, tasks, tool=tool)
    X, Y, Z, A, B, C = _numbers(re.search(r"DECL GLOBAL FRAME videocal_tool=\{([^}]*)\}", krl).group(1))
    R = Rotation.from_euler("ZYX", [A, B, C], degrees=True).as_matrix()
    assert np.allclose([X, Y, Z], tool[:3, 3], atol=1e-3) and np.allclose(R, tool[:3, :3], atol=1e-5)
    fanuc = controller_listing("fanuc", t, tasks, tool=tool)
    values = _numbers(re.search(r"! (X [^;]*) ;", fanuc).group(1))
    assert np.allclose(values[:3], tool[:3, 3], atol=1e-3) and np.allclose(
        Rotation.from_euler("xyz", values[3:], degrees=True).as_matrix(), tool[:3, :3], atol=1e-5
    )
    assert "$TOOL := POS(12.500, -3.000, 187.250," in controller_listing("pdl2", t, tasks, tool=tool)
    assert "videocal_tool" not in controller_listing("krl", t, tasks)  # no robot given: no tool data, nothing made up


def test_a_fanuc_listing_carries_no_configuration_a_controller_would_load(table):
    """It carried CONFIG : 'N U T, 0, 0, 0', which a controller loads as it is: a guess at the arm's configuration.
    Each position now says it is not known, in a form the controller refuses, and the remarks say to teach it."""
    import re

    from calib_core.workspace.controller_formats import FANUC_UNTAUGHT

    t, tasks = table
    listing = controller_listing("fanuc", t, tasks, "cell_targets")
    configs = re.findall(r"CONFIG : '([^']*)'", listing)
    assert configs and set(configs) == {FANUC_UNTAUGHT}
    # FANUC's form: a flip, an up/down and a top/bottom letter, then three turn numbers; this is none
    assert not re.fullmatch(r"[FN] [UD] [TB], -?\d, -?\d, -?\d", FANUC_UNTAUGHT)
    assert "teach it (TOUCHUP) before use" in listing
