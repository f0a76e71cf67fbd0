"""Make ``resources/recordings/sample_session.mcap``: a short calibration on the simulated test bed.

Frames at 320 x 240 (to keep the file small), joint samples, the picks as events, two solves and a
stored correction. Run from the project root: ``.venv/bin/python scripts/make_sample_recording.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from calib_core.calibration.session import CalibrationSession
from calib_core.camera.projection import project
from calib_core.frames import apply, invert
from calib_core.recording.recorder import SessionRecorder
from calib_core.robot import solve_ik
from calib_core.testbed.test_bed import TestBed

OUT = Path(__file__).resolve().parents[1] / "resources" / "recordings" / "sample_session.mcap"
FEATURES = ["plate_top_left", "plate_top_right", "plate_bottom_right", "plate_bottom_left", "pin_tip", "boss_top_left"]


def main() -> None:
    bed = TestBed.create()
    cell = bed.workcell
    task = cell.task("oru_1_grasp")
    q = solve_ik(bed.model_robot, task.approach2base, cell.home_joints_deg).q_deg
    bed.joints_deg = q
    small = bed.intrinsics.scaled(0.25)
    camera = bed.camera(intrinsics=small, seed=1)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(5)
    with SessionRecorder(OUT, drop_when_busy=False) as rec:
        rec.record_setup(workcell="resources/workcell/workcell.yaml", intrinsics=bed.intrinsics.to_dict(), task=task.name, target="oru_1_fixture")
        for i in range(6):
            frame = camera.read()
            rec.record_frame(frame.image, frame.t_host_s)
            rec.record_joints(i, 1000 + 100 * i, time.monotonic(), q)
        session = CalibrationSession()
        session.set_target("oru_1_fixture")
        fx = cell.component("oru_1_fixture")
        true_cam = bed.true_cam2world(q)
        for name in FEATURES:
            p = apply(fx.item2world, fx.features[name])
            number = session.pick_3d("oru_1_fixture", name, p)
            pixel = project(apply(invert(true_cam), p[None]), bed.intrinsics)[0] + rng.normal(0, 0.3, 2)
            session.pick_2d(pixel)
            rec.record_event("pick", number=number, component="oru_1_fixture", feature=name, point_world_mm=p.tolist(), pixel=pixel.tolist())
        for robust in (False, True):
            session.robust = robust
            est = session.calibrate(bed.intrinsics, fx.item2world, bed.model_cam2world(q), bed.model_robot.fk(q), q)
            rec.record_solve(session.last_solve_inputs, est.solution.to_dict())
        c = session.store_correction(task.name)
        rec.record_correction({"task": c.task, "displacement_mm": c.displacement_mm, "rotation_deg": c.rotation_deg, "std_displacement_mm": c.std_displacement_mm, "std_rotation_deg": c.std_rotation_deg, "joints_deg": c.joints_deg, "rms_px": c.rms_px, "pairs": c.pairs})
    camera.close()
    print(f"wrote {OUT} ({OUT.stat().st_size // 1024} KiB)")


if __name__ == "__main__":
    main()
