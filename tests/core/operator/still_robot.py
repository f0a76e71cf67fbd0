"""Feeding the operator core a still robot and a camera frame, as the link and the camera would."""

import time

import numpy as np

from calib_core.connectors.link_types import TimedSample
from calib_core.link.protocol import JointSample
from calib_core.connectors.frame import Frame

_seq = iter(range(10**9))


def sample(core, joints_deg, t_s: float) -> None:
    """One joint sample (model joints) at host time ``t_s``, through the core's own entry point."""
    q = core.cell.joint_map.to_controller(np.asarray(joints_deg, dtype=float))
    core.arm.observe_sample(TimedSample(JointSample(next(_seq), int(t_s * 1000), tuple(float(v) for v in q)), t_s))


def still_for(
    core, seconds: float = 0.6, joints_deg=None, rate_hz: float = 50.0, start_s: float | None = None
) -> float:
    """Samples of a robot standing at ``joints_deg`` (default: the core's joints) for ``seconds``
    from ``start_s`` (default: the last ``seconds`` up to now); returns the time of the last one."""
    q = core.joints_deg if joints_deg is None else joints_deg
    start = time.monotonic() - seconds if start_s is None else start_s
    times = start + np.arange(int(seconds * rate_hz) + 1) / rate_hz
    for t in times:
        sample(core, q, float(t))
    return float(times[-1])


def frame_now(core, index: int = 0, image=None, t_s: float | None = None) -> Frame:
    """A camera frame captured at ``t_s`` (default: the newest joint sample's time, or now) given to the core."""
    if t_s is None:
        t_s = core.observations.history.latest_s or time.monotonic()
    frame = Frame(np.zeros((480, 640, 3), np.uint8) if image is None else image, index, t_s)
    core.frames.observe_frame(frame)
    return frame


def core_looking_at_task(**cell_options):
    """An operator core on the simulated cell with the robot standing at the task's approach and a frame of its
    camera held as frame 3: ``(core, site, joints_deg, camera)``; the caller closes the camera."""
    from calib_core.operator.core import OperatorCore
    from calib_core.robot import solve_ik
    from videocal_sim.sim_site import simulated_cell

    cell, site = simulated_cell(**cell_options)
    core = OperatorCore(cell, site)
    q = solve_ik(core.robot, core.task.approach2base, core.cell.home_joints).q_deg
    site.bed.joints_deg = q
    camera = site.camera_factory()()
    still_for(core, joints_deg=q)
    frame_now(core, index=3, image=camera.read().image)
    return core, site, q, camera
