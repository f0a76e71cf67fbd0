"""new-cell puts the floor under the robot's mounting, not at its ``base`` frame: on FANUC's and Yaskawa's
ROS-Industrial packages ``base`` stands 330 mm above ``base_link``, and the robot's base stood under the floor in
every view. KUKA's KR6 (``base`` at ``base_link``) keeps its floor at 0; the same package with its ``base`` raised
330 mm, as FANUC's is, gets the floor 330 mm down."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from calib_core.robot.visuals import RobotVisuals
from calib_core.workcell import load_workcell
from calib_core.workcell.starter import write_starter_cell

KUKA = Path(__file__).parents[2] / "data" / "third_party" / "ros_industrial" / "kuka_experimental"


def _mounting_bottom_mm(cell) -> float:
    robot = cell.load_robot()
    visuals = RobotVisuals.from_robot(robot)
    poses = visuals.poses(cell.home_joints_deg)
    return min(
        float(trimesh.transform_points(trimesh.bounds.corners(m.bounds), p)[:, 2].min())
        for g, m, p in zip(visuals.geometry_model.geometryObjects, visuals.meshes, poses)
        if g.parentJoint == 0
    )


@pytest.mark.parametrize("base_height_m", [0.0, 0.330])
def test_the_floor_is_under_the_robot_s_mounting(tmp_path, base_height_m):
    package = tmp_path / "kuka_experimental"
    shutil.copytree(KUKA, package)
    macro = package / "kuka_kr6_support" / "urdf" / "kr6r900sixx_macro.xacro"
    text = macro.read_text()
    text, n = re.subn(
        r'(<joint name="\$\{prefix\}base_link-base" type="fixed">\s*<origin xyz=")0 0 0(")',
        rf"\g<1>0 0 {base_height_m}\g<2>",
        text,
    )
    assert n == 1
    macro.write_text(text)
    made = write_starter_cell(tmp_path / "cell", package / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", [package])
    cell = load_workcell(made.workcell_path)
    floor = cell.component("floor")
    floor_top = floor.item2world[2, 3] + floor.mesh.bounds[1, 2]
    bottom = _mounting_bottom_mm(cell)
    assert bottom == pytest.approx(-1000.0 * base_height_m, abs=5.0)  # the mounting's bottom, in the base frame
    assert floor_top == pytest.approx(min(0.0, bottom), abs=0.01)
    target = cell.component("target")
    lowest = float(trimesh.transform_points(target.mesh.vertices, target.item2world)[:, 2].min())
    assert lowest <= floor_top + 25.0  # the target's post reaches down to the floor
    assert np.isclose(floor.item2world[:3, :3], np.eye(3)).all()
