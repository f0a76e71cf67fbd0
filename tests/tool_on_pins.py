"""The check a robot calibration with grasps must pass: its calibrated URDF puts the TCP on each task's pin."""

import numpy as np

from calib_core.frames import pose_difference
from calib_core.robot.model import load_robot


def assert_tool_on_the_pins(urdf, bed, grasps: dict, within_mm: float = 0.5) -> None:
    """At each grasp's joints (``grasps``: task name -> joints) the calibrated robot's TCP is within ``within_mm``
    of the task's pin as surveyed, at least four times closer than the nominal model's, and turned under 0.02 deg.
    Board views alone leave the base untied (no surveyed component), so the grasps' tools differ by a few tenths of
    a millimetre: their mean puts each pin within that."""
    robot = load_robot(urdf)
    for name, q in grasps.items():
        pin = bed.workcell.task(name).tcp2base
        d, r = pose_difference(robot.fk(q, "tcp"), pin)
        nominal = np.linalg.norm(pose_difference(bed.model_robot.fk(q, "tcp"), pin)[0])
        assert np.linalg.norm(d) < within_mm and np.linalg.norm(d) < nominal / 4 and np.linalg.norm(r) < 0.02, (
            name,
            d,
            r,
            nominal,
        )
