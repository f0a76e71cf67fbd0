"""A simulated controller started at joints whose first is below zero: the joints went to the child as two tokens,
and argparse read "-20.2,..." as an option ("expected one argument"); the Franka Panda's new cell starts there."""

import numpy as np

from calib_core.bundled import DEFAULT_WORKCELL
from calib_core.connectors.controller import ControllerContext
from calib_core.connectors.registry import open_controller
from calib_core.connectors.joint_map import JointMap
from calib_core.connectors.link_types import LinkState
from tests.waiting import wait_until
from videocal_sim.sim_process import SimulatorProcess


def test_the_simulated_controller_starts_at_a_negative_first_joint():
    start = np.array([-20.25, 10.0, 30.0, 0.0, -45.0, 5.0])
    sim = SimulatorProcess(DEFAULT_WORKCELL, start, tcp=True)
    try:
        url = sim.wait_ready()
        names = tuple(f"j{k}" for k in range(6))
        link = open_controller(url, ControllerContext(names, ("deg",) * 6, JointMap.identity(6), 50.0)).start()
        try:
            assert wait_until(lambda: link.state is LinkState.UP and link.latest is not None, 20.0)
            assert np.allclose(link.latest.sample.joints_deg, start, atol=1e-3)
        finally:
            link.close()
    finally:
        sim.stop()
