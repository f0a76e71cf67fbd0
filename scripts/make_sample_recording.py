"""Make ``resources/recordings/sample_session.mcap``: a short calibration on the simulated test bed,
recorded through the operator core and its recording tap, exactly as the window records one.

The robot drives from home to the task location ``oru_1_grasp``, where a look counts for it (joints at 50 Hz,
1280 x 960 H.264 frames at 15 fps), settles, then the operator picks six pairs on the held frame,
solves twice (plain and robust) and stores the correction, with the camera running throughout.
The session runs in simulated time, so the file has the rates it states on any machine (rendering
a frame takes longer than 1/15 s here); every stamp in it comes from that one clock. Run from the
project root: ``.venv/bin/python scripts/make_sample_recording.py [--out FILE.mcap]``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from calib_core.calibration.errors import ConfirmationNeeded
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.connectors.link_types import TimedSample
from calib_core.link.protocol import JointSample
from calib_core.operator.core import OperatorCore
from calib_core.robot import solve_ik
from videocal_sim.sim_site import simulated_cell
from calib_core.connectors.frame import Frame

OUT = Path(__file__).resolve().parents[1] / "resources" / "recordings" / "sample_session.mcap"
FEATURES = ["plate_top_left", "plate_top_right", "plate_bottom_right", "plate_bottom_left", "pin_tip", "boss_top_left"]
DRIVE_S, SETTLE_S, STEP_S, FPS, JOINT_HZ = 3.0, 0.8, 0.6, 15.0, 50.0


class SimulatedClock:
    def __init__(self, t_s: float):
        self.t_s = t_s

    def __call__(self) -> float:
        return self.t_s


def main(out: Path = OUT) -> None:
    """Record the session into ``out`` (written whole or not at all)."""
    cell, site = simulated_cell()
    bed = site.bed
    core = OperatorCore(cell, site)
    core.set_task("oru_1_grasp")
    q_home = np.array(cell.home_joints, dtype=float)
    q_task = solve_ik(core.robot, core.task.tcp2base, q_home).q_deg  # (a look counts where it is made)
    camera = bed.camera(seed=1)
    rng = np.random.default_rng(5)
    clock = SimulatedClock(1000.0)
    out.parent.mkdir(parents=True, exist_ok=True)
    part = out.with_name(out.stem + ".part.mcap")  # (the sample is replaced only by a whole recording)
    core.recording.start(part, clock=clock, drop_when_busy=False)
    start = clock.t_s
    steps = [("pick", name) for name in FEATURES] + [("solve", False), ("solve", True), ("store", None), ("idle", None)]
    next_step = start + DRIVE_S + SETTLE_S
    n_joint = n_frame = 0
    while steps:
        t_joint, t_frame = start + n_joint / JOINT_HZ, start + n_frame / FPS
        clock.t_s = min(t_joint, t_frame, next_step)
        s = min(1.0, (clock.t_s - start) / DRIVE_S)
        bed.joints_deg = q_home + (q_task - q_home) * (3 * s * s - 2 * s * s * s)  # smooth start and stop
        if clock.t_s == t_joint:
            q = cell.joint_map.to_controller(bed.joints_deg)
            core.arm.observe_sample(
                TimedSample(JointSample(n_joint, int(round(20 * n_joint)), tuple(float(v) for v in q)), clock.t_s)
            )
            n_joint += 1
        elif clock.t_s == t_frame:
            image, _ = camera.render(bed.joints_deg)
            core.frames.observe_frame(Frame(image, n_frame, clock.t_s))
            n_frame += 1
        else:
            kind, arg = steps.pop(0)
            if kind == "pick":
                fixture = core.workcell.component(core.task.component)
                p = apply(fixture.item2world, fixture.features[arg])
                core.picking.pick_model_point(fixture.name, arg, p)
                true_pixel = project(apply(invert(bed.true_cam2world(bed.joints_deg)), p[None]), core.intrinsics)[0]
                core.picking.pick_image_point(true_pixel + rng.normal(0, 0.3, 2))  # an operator's click, 0.3 px off
                core.picking.accept_pair()
            elif kind == "solve":
                core.session.options.robust = arg
                core.picking.calibrate()
            elif kind == "store":
                try:
                    core.desk.store_correction()
                except ConfirmationNeeded as why:
                    core.desk.store_correction(confirmation=f"sample recording: {why}")
            next_step += STEP_S
    rec = core.recording.recorder
    core.recording.stop()
    camera.close()
    part.replace(out)
    duration = clock.t_s - start
    print(
        f"wrote {out} ({out.stat().st_size // 1024} KiB, {duration:.1f} s: {rec.frames_written} frames at {FPS:g} fps, "
        f"{n_joint} joint samples at {JOINT_HZ:g} Hz)"
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT, help=f"the recording to write (default {OUT})")
    main(parser.parse_args().out)
