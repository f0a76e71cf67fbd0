"""Which frame new-cell mounts the tool on: the JACO2 of example-robot-data got a finger tip
(``j2s6s200_link_finger_tip_2``): tool and camera 150 mm sideways, and the demo still said ok. The flange is now
the last link of the arm before any gripper, said with its reason, and a flange whose z does not point out of
the wrist (JACO2's end effector: 90 deg across) has the tool placed along the way out."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from calib_core.robot.model import RobotSpec, load_robot
from calib_core.workcell import load_workcell
from calib_core.workcell.flange_choice import choose_flange as _choose_flange, tool_alignment
from tests.vendor_robots import JACO2, PANDA, SHARE, UR5, Z1, require

KR6 = Path(__file__).resolve().parents[1] / "data" / "third_party" / "ros_industrial" / "kuka_experimental"


def _robot(urdf: Path, packages=(SHARE,)):
    return load_robot(RobotSpec(require(urdf) if urdf.suffix == ".urdf" else urdf, tuple(packages), {"base": None}))


@pytest.mark.parametrize(
    "urdf, packages, flange, turned",
    [
        (JACO2, (SHARE,), "j2s6s200_end_effector", True),
        (PANDA, (SHARE,), "panda_hand", False),  # the moving fingers branch off there; not the hand's TCP frame
        (UR5, (SHARE,), "tool0", False),
        (Z1, (SHARE,), "gripperStator", True),  # its jointGripper ends the arm
        (KR6 / "kuka_kr6_support" / "urdf" / "kr6r900sixx.xacro", (KR6,), "tool0", False),
    ],
)
def test_the_flange_is_the_arm_s_last_link_never_a_finger(urdf, packages, flange, turned):
    robot = _robot(urdf, packages)
    choice = _choose_flange(robot, None)
    assert choice.name == flange, choice
    assert "finger" not in choice.name and choice.why
    align, words = tool_alignment(robot, choice.name)
    assert (words is not None) == turned
    if turned:
        # the tool's z (the aligned one) points out of the wrist
        q = np.clip(np.zeros(robot.n_joints), robot.lower_limits_deg, robot.upper_limits_deg)
        flange2base = robot.fk(q, flange)
        wrist = robot.fk(q, robot.model.names[robot.model.frames[robot.frame_id(flange)].parentJoint])[:3, 3]
        out = (flange2base[:3, 3] - wrist) / np.linalg.norm(flange2base[:3, 3] - wrist)
        assert (flange2base @ align)[:3, 2] @ out > 0.999
        np.testing.assert_allclose(align[:3, :3] @ align[:3, :3].T, np.eye(3), atol=1e-12)


def test_new_cell_on_the_jaco2_says_which_flange_and_puts_the_tool_out_of_the_hand(tmp_path):
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "new-cell",
            str(tmp_path / "jaco"),
            "--urdf",
            str(require(JACO2)),
            "--package-path",
            str(SHARE),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    assert (
        "flange j2s6s200_end_effector (" in run.stdout and "finger" in run.stdout
    )  # the fingers it left out are named
    assert "warning: the z axis of 'j2s6s200_end_effector'" in run.stdout
    cell = load_workcell(tmp_path / "jaco" / "workcell.yaml")
    robot = cell.load_robot()
    q = np.asarray(cell.home_joints_deg, float)
    tcp, flange = robot.fk(q, "tcp"), robot.fk(q, "flange")
    wrist = robot.fk(q, "j2s6s200_joint_6")[:3, 3]
    out = (flange[:3, 3] - wrist) / np.linalg.norm(flange[:3, 3] - wrist)
    along = tcp[:3, 3] - flange[:3, 3]
    # the TCP lies beyond the hand along the way out (it went 150 mm sideways), and its z points that way
    assert np.linalg.norm(along - (along @ out) * out) < 1.0 and along @ out > 100.0
    assert tcp[:3, 2] @ out > 0.999


def test_a_cell_name_and_a_urdf_file_name_with_a_newline_and_a_hash_are_written_as_yaml_strings(tmp_path):
    """new-cell wrote the URDF's file name into workcell.yaml as it was: a newline in it made another YAML key."""
    import shutil

    odd = tmp_path / "ur5 #1\nrobot.urdf"
    shutil.copyfile(require(UR5), odd)
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "app.cli.main",
            "new-cell",
            str(tmp_path / "cell"),
            "--urdf",
            str(odd),
            "--package-path",
            str(SHARE),
            "--name",
            "line one\nname: injected # not a comment",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr
    cell = load_workcell(tmp_path / "cell" / "workcell.yaml")
    assert cell.name == "line one\nname: injected # not a comment"
    assert cell.robot_spec.urdf.resolve() == odd.resolve()
