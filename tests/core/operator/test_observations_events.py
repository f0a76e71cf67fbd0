"""The frames model (``core.observations``) is one object for the program's life: a listener connected
once hears the live frames, a replay's frames and the live ones again; the held frame is told only when
it changes; a replay drops what the live source had (its joints are stale by the time it ends)."""

import numpy as np

from calib_core.link.joint_history import JointHistory
from calib_core.operator.core import OperatorCore
from calib_core.connectors.frame import Frame
from videocal_sim.sim_site import simulated_cell
from tests.core.operator.still_robot import frame_now, still_for


def test_one_model_across_a_replay_and_the_still_told_only_on_change():
    cell, site = simulated_cell(image_scale=0.5)
    core = OperatorCore(cell, site)
    obs = core.observations
    frames, stills, sources = [], [], []
    obs.frame_observed.connect(frames.append)
    obs.still_changed.connect(stills.append)
    obs.source_changed.connect(sources.append)

    still_for(core)
    live = frame_now(core, index=1)
    held = core.frames.hold_frame()
    core.frames.release_frame()
    core.frames.release_frame()  # nothing held: nothing to tell
    assert frames == [live] and stills == [held, None]

    core.frames.hold_frame()
    times = np.linspace(0.0, 2.0, 101)
    core.frames.begin_replay(
        JointHistory.from_arrays(times, np.tile(core.joints_deg, (len(times), 1)), core.workcell.safety.settle_rule),
        "take.mcap",
    )
    assert core.observations is obs and core.frames.replaying and sources == ["take.mcap"]
    assert stills[-1] is None and obs.still is None  # a replay lets the live still go
    assert obs.latest is None  # the live frames are not the recording's
    frame_now(core, index=2)  # a live frame during a replay is not observed
    replayed = Frame(np.zeros((480, 640, 3), np.uint8), 5, 2.0)
    core.frames.observe_frame(replayed, replayed=True)
    assert frames[-1] is replayed and len(frames) == 2
    assert obs.stamp(replayed).source == "take.mcap"

    core.frames.end_replay()
    assert not core.frames.replaying and sources == ["take.mcap", "live"] and obs.latest is None
    still_for(core)
    again = frame_now(core, index=3)
    assert frames[-1] is again and obs.history is obs.live_history
