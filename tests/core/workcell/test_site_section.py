"""The workcell's ``site:`` section: checked at load, paths made absolute against the workcell's folder."""

from __future__ import annotations

import pytest

from calib_core.errors import FileFormatError
from calib_core.workcell import DEFAULT_WORKCELL
from calib_core.workcell.loader import load_site_section, load_workcell


def _cell_with(tmp_path, site_text: str):
    text = DEFAULT_WORKCELL.read_text()
    path = tmp_path / "cell.yaml"
    # the bundled cell's relative files stay reachable: write it beside them through absolute paths
    path.write_text(text.replace("\nrobot:", f"\n{site_text}\nrobot:", 1))
    return path


def test_a_site_section_is_read_with_its_camera_path_made_absolute(tmp_path):
    path = _cell_with(
        tmp_path,
        "site:\n  controller: ros2:///joint_states\n  camera: shots\n  controller_options: {trajectory_controller: "
        "arm_controller}",
    )
    section = load_site_section(path)
    assert section.controller == "ros2:///joint_states"
    assert section.camera == str((tmp_path / "shots").resolve())
    assert section.controller_options == {"trajectory_controller": "arm_controller"}


def test_a_bundled_cell_has_no_site_section():
    assert load_site_section(DEFAULT_WORKCELL) is None
    assert load_workcell(DEFAULT_WORKCELL).site is None


@pytest.mark.parametrize(
    "site, field",
    [
        ("site:\n  controller: 42", "site.controller"),
        ("site:\n  camera: ''", "site.camera"),
        ("site:\n  cameras: 0", "site"),
        ("site:\n  camera_options: [1, 2]", "site.camera_options"),
        ("site:\n  controller_options: {speed: [1]}", "site.controller_options.speed"),
    ],
)
def test_a_wrong_site_section_names_its_field(tmp_path, site, field):
    with pytest.raises(FileFormatError) as info:
        load_site_section(_cell_with(tmp_path, site))
    assert field in str(info.value)
