"""``demo --site ros2`` started its simulated arm on the workstation's own ROS domain (0 by default), where a real
robot's controller may listen. Without ROS_DOMAIN_ID it now takes a private domain; with it, that one."""

from __future__ import annotations

from videocal_sim.ros2_site import PRIVATE_DOMAINS, Ros2SimulatedSite, private_domain
from videocal_sim.sim_site import simulated_cell


def test_a_private_domain_unless_ros_domain_id_is_set(monkeypatch):
    _, site = simulated_cell()
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    private = Ros2SimulatedSite(site)
    try:
        assert PRIVATE_DOMAINS[0] <= private.domain <= PRIVATE_DOMAINS[1] and private.domain == private_domain()
        assert "a private one" in private.description
    finally:
        private.close()
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    chosen = Ros2SimulatedSite(site)
    try:
        assert chosen.domain == 7 and "private" not in chosen.description
    finally:
        chosen.close()
