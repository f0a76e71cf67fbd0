"""Third-party robot descriptions for the tests: the UR5 and the Franka Panda of the
``example-robot-data`` package (a test dependency, BSD-3-Clause), with their vendor meshes."""

from __future__ import annotations

import sysconfig
from pathlib import Path

import pytest

SHARE = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share"
ROBOTS = SHARE / "example-robot-data" / "robots"
UR5 = ROBOTS / "ur_description" / "urdf" / "ur5_robot.urdf"
PANDA = ROBOTS / "panda_description" / "urdf" / "panda.urdf"
JACO2 = ROBOTS / "kinova_description" / "robots" / "kinova.urdf"  # Kinova JACO2 j2s6s200, fingers fixed
Z1 = ROBOTS / "z1_description" / "urdf" / "z1.urdf"  # Unitree Z1, a moving gripper joint


def require(path: Path) -> Path:
    if not path.is_file():
        pytest.fail(f"{path} is missing: install the test dependencies (pip install -e '.[test]': example-robot-data)")
    return path
