"""The demo's cell: the simulated robot (typical joint, link and base errors, the modelled camera mounting) reached
the way ``--site`` names (in process, over ROS 2, GigE Vision or a UR controller), near or through a far link."""

from __future__ import annotations

from pathlib import Path

from calib_core.workcell import load_workcell
from videocal_sim.sim_site import simulated_cell
from videocal_sim.true_robot import RobotErrors


def demo_site(workcell: Path, *, scale: float, site_kind: str, link_delay_ms: float, look: str):
    """(workcell, site) of the demo: the cell ``workcell`` with a simulated robot and camera (images at ``scale`` of
    full size; ``look`` ``"workshop"`` for the less kind camera), reached by ``site_kind``; ``link_delay_ms`` one way
    (with a far link's spread and losses) when not 0. A site kind and a delay that do not go together raise
    :class:`ValueError`."""
    # One view cannot see an error in the camera's mounting (a hand-eye calibration takes the robot's kinematics
    # as exact): the demo's true robot has typical joint, link and base errors and the modelled camera mounting.
    n_joints = load_workcell(workcell).load_robot().n_joints
    typical = RobotErrors.typical(0, n_joints=n_joints)
    cell, site = simulated_cell(
        workcell,
        errors=RobotErrors(
            typical.joint_offsets_deg, typical.link_errors_mm, typical.base_xyz_mm, typical.base_rpy_deg
        ),
        image_scale=scale,
        less_kind=look == "workshop",
    )
    weather = None
    if link_delay_ms:  # the same cell far away, with a far link's weather
        from videocal_sim.delay_line import LinkWeather

        weather = LinkWeather(link_delay_ms / 1000.0, 0.3, 0.01)
        if site_kind not in ("sim", "ros2"):
            raise ValueError(
                "--link-delay-ms crosses videocal's own link (--site sim) or ROS 2's (--site ros2), not --site "
                f"{site_kind}"
            )
    if site_kind == "ros2":  # the same simulated cell, its robot and camera reached through ROS 2
        from videocal_sim.ros2_site import Ros2SimulatedSite

        site = Ros2SimulatedSite(site, weather=weather)
    elif site_kind == "gige":  # the same cell, its camera served over GigE Vision and read through Aravis
        from videocal_sim.gige_site import GigESimulatedSite

        site = GigESimulatedSite(site)
    elif site_kind == "ur":  # the same cell, its robot a simulated UR controller reached through ur_rtde and URScript
        from videocal_sim.ur_site import URSimulatedSite

        site = URSimulatedSite(site)
    if weather is not None and site_kind == "sim":  # videocal's own link through a delay line
        from videocal_sim.far_site import FarSimulatedSite

        site = FarSimulatedSite(site, weather)
    return cell, site


def camera_url(site_kind: str) -> str:
    """How the demo's window reads the camera, for the report."""
    return {"ros2": "ros2:///camera/image_raw", "gige": "aravis://127.0.0.1"}.get(
        site_kind, "the simulated camera (in process)"
    )
