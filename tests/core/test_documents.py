"""The reading layer and the files it guards: limits on size, nesting and aliases; hand-eye files with
non-finite numbers or other units; robot descriptions with a NaN origin or limits out of order."""

import json
import math
import re
import time

import pytest
import yaml

from calib_core.documents import finite_number, parse_json, parse_yaml, read_text
from calib_core.errors import FileFormatError
from calib_core.robot.description import read_description
from calib_core.robot.model import DEFAULT_URDF
from calib_core.vision.hand_eye_io import load_cam2flange


def test_sizes_are_checked_before_reading(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"# " + b"x" * 2000)
    with pytest.raises(FileFormatError, match=r"big.yaml: is 2.0 kB; a workcell file is at most 1.0 kB"):
        read_text(path, "workcell file", max_bytes=1000)
    assert read_text(path, "workcell file", max_bytes=3000).startswith("# x")
    (tmp_path / "latin1.yaml").write_bytes("name: caf\xe9".encode("latin-1"))
    with pytest.raises(FileFormatError, match="not UTF-8 text"):
        read_text(tmp_path / "latin1.yaml", "workcell file")


def test_an_alias_bomb_is_refused_before_it_is_built():
    bomb = "a0: &a0 [x]\n" + "".join(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]\n" for i in range(1, 12))
    started = time.process_time()
    with pytest.raises(FileFormatError, match="more than 64 YAML aliases"):
        parse_yaml(bomb + "name: *a11\n", "cell.yaml")
    assert time.process_time() - started < 5.0  # refused on the events, not after building 9**11 references
    assert parse_yaml("a: &x [1, 2]\nb: *x\n", "ok.yaml") == {"a": [1, 2], "b": [1, 2]}  # a few aliases are fine


@pytest.mark.parametrize(
    "text, kind",
    [
        ("[" * 100 + "]" * 100, "json"),
        ("[" * 100 + "]" * 100, "yaml"),
        ("a:\n" + "".join("  " * i + "- \n" for i in range(1, 80)), "yaml"),
    ],
)
def test_deep_nesting_is_refused(text, kind):
    parse = parse_json if kind == "json" else parse_yaml
    with pytest.raises(FileFormatError, match="nests deeper than 64 levels"):
        parse(text, f"deep.{kind}")
    ten = "[" * 10 + "]" * 10
    assert parse(ten, f"ok.{kind}") == json.loads(ten)  # real documents nest a few levels: well inside


def test_finite_numbers_name_their_field():
    assert finite_number(3, "f.yaml", "a.b", low=0) == 3.0
    for bad in (math.nan, math.inf, "3", True, None):
        with pytest.raises(FileFormatError, match=re.escape("f.yaml: field 'a.b'")):
            finite_number(bad, "f.yaml", "a.b")
    with pytest.raises(FileFormatError, match="above 0"):
        finite_number(0, "f.yaml", "a.b", low=0, exclusive_low=True)


def _hand_eye(tmp_path, doc) -> object:
    path = tmp_path / "he.yaml"
    path.write_text(yaml.safe_dump(doc) if isinstance(doc, dict) else doc)
    return path


def test_hand_eye_files_with_non_finite_numbers_or_other_units_are_refused(tmp_path):
    good = {
        "cam2flange": {"xyz": [81.0, -1.0, 88.0], "rpy": [-100.0, 0.0, -90.0]},
        "units": {"length": "mm", "angle": "deg"},
    }
    assert load_cam2flange(_hand_eye(tmp_path, good))[0, 3] == pytest.approx(81.0)
    for value, field in ((".nan", "cam2flange.xyz[1]"), (".inf", "cam2flange.xyz[1]")):
        text = yaml.safe_dump(good).replace("- -1.0", f"- {value}")
        with pytest.raises(FileFormatError, match=re.escape(f"field '{field}': must be a finite number")):
            load_cam2flange(_hand_eye(tmp_path, text))
    with pytest.raises(FileFormatError, match="field 'units'.*mm and deg"):
        load_cam2flange(_hand_eye(tmp_path, {**good, "units": {"length": "m", "angle": "deg"}}))
    with pytest.raises(FileFormatError, match=r"field 'cam2flange.rpy': must be a list of 3 numbers"):
        load_cam2flange(_hand_eye(tmp_path, {"cam2flange": {"xyz": [1, 2, 3], "rpy": "0 0 0"}}))


def test_a_robot_description_with_a_nan_origin_or_limits_out_of_order_is_refused(tmp_path):
    text = DEFAULT_URDF.read_text()
    nan_origin = tmp_path / "nan.urdf"
    nan_origin.write_text(re.sub(r'(<visual>\s*<origin xyz=")[^"]*"', r'\1nan 0 0"', text, count=1))
    assert nan_origin.read_text() != text
    with pytest.raises(FileFormatError, match=r"origin xyz='nan 0 0' must be three finite numbers"):
        read_description(nan_origin)
    swapped = tmp_path / "limits.urdf"
    first = re.search(r'<limit[^>]*lower="([^"]+)"[^>]*upper="([^"]+)"', text)
    swapped.write_text(
        text[: first.start()]
        + first.group(0)
        .replace(f'lower="{first.group(1)}"', 'lower="9"')
        .replace(f'upper="{first.group(2)}"', 'upper="-9"')
        + text[first.end() :]
    )
    with pytest.raises(FileFormatError, match=r"limit lower \(9\) is above upper \(-9\)"):
        read_description(swapped)
